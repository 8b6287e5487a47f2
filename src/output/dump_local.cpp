// `dump ID group local N file value ...` (LAMMPS text format): one line per
// local datum of computes that give local values (compute pair/gran/local,
// wall/gran/local), the values being `index` (1..N over all ranks), `c_ID`
// (a local vector) or `c_ID[I]` (column I of a local array). All computes of
// one dump must give the same number of rows. Rows are gathered to rank 0 in
// rank order and written there. See doc/commands/dump.md.
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <string>
#include <vector>

#include "compute/compute.h"
#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "output/dump.h"
#include "output/dump_custom.h"

namespace granary {

namespace {

struct LocalValue {
  std::string name;  // as written: "index", "c_ID", "c_ID[3]"
  bool index = false;
  std::string compute;
  int col = 0;  // 0: a local vector; i >= 1: column i of a local array
};

class DumpLocal : public Dump {
 public:
  DumpLocal(Engine& engine, const Args& args) : Dump(engine, args) {
    const std::string where = "dump " + id + " local";
    if (args.size() < 6)
      throw InputError(where + ": usage: dump ID group-ID local N file value ... (index, c_ID, c_ID[I])");
    if (filename.size() > 3 && filename.compare(filename.size() - 3, 3, ".gz") == 0)
      throw InputError(where +
                       ": compressed text dumps (.gz) are not supported; compress the files afterwards");
    if (filename.find('%') != std::string::npos)
      throw InputError(where +
                       ": '%' (one file per rank) is not supported; the rows are gathered on one rank");
    for (std::size_t k = 5; k < args.size(); ++k) {
      const std::string& w = args[k];
      LocalValue v;
      v.name = w;
      if (w == "index") {
        v.index = true;
      } else if (w.rfind("c_", 0) == 0 && w.size() > 2) {
        std::string body = w.substr(2);
        const auto open = body.find('[');
        if (open != std::string::npos) {
          if (body.back() != ']') throw InputError(where + ": value '" + w + "' has an unclosed '['");
          const std::string col = body.substr(open + 1, body.size() - open - 2);
          v.col = static_cast<int>(parse_int(col, where + " " + w));
          if (v.col < 1) throw InputError(where + ": the column of '" + w + "' must be 1 or more");
          body = body.substr(0, open);
        }
        v.compute = body;
      } else if (w.rfind("f_", 0) == 0) {
        throw InputError(where + ": '" + w +
                         "': no fix of Granary gives local values; use the local values of a compute "
                         "(c_ID, c_ID[I])");
      } else {
        throw InputError(where + ": unknown value '" + w +
                         "'; expected index, c_ID or c_ID[I] of a compute that gives local values "
                         "(e.g. compute pair/gran/local)");
      }
      values_.push_back(v);
      columns_ += (columns_.empty() ? "" : " ") + w;
    }
    multifile_ = filename.find('*') != std::string::npos;
    dumpio::check_directory(engine.world, filename, "dump " + id);
    formats_.resize(static_cast<int>(values_.size()));
    check(false);
  }

  ~DumpLocal() override { finish(); }

  void finish() override {
    if (fp_) {
      std::fclose(fp_);
      fp_ = nullptr;
    }
  }

  void init() override {
    check(false);
    build_formats();
  }

  int modify_param(const Args& args, std::size_t k) override {
    const std::string& key = args[k];
    const bool has1 = k + 1 < args.size();
    const std::string where = "dump_modify " + id + " " + key;
    if (const int used = formats_.modify_param(args, k, where)) return used;
    const int ncols = static_cast<int>(values_.size());
    if (key == "sort" && has1) {
      const std::string& v = args[k + 1];
      if (v == "off") {
        sort_ = 0;
      } else {
        const long long c = v == "id" ? 0 : parse_int(v, where);
        if (c == 0 || std::llabs(c) > ncols)
          throw InputError(where + ": dump local sorts by a column, off or +-1.." + std::to_string(ncols));
        sort_ = static_cast<int>(c);
      }
      return 2;
    }
    if (key == "pad" && has1) {
      const long long n = parse_int(args[k + 1], where);
      if (n < 0 || n > 30) throw InputError(where + ": pad must be 0..30");
      pad_ = static_cast<int>(n);
      return 2;
    }
    if (key == "append" && has1) return append_ = parse_bool(args[k + 1], where), 2;
    if (key == "flush" && has1) return parse_bool(args[k + 1], where), 2;  // frames are always flushed
    if (key == "label" && has1) return label_ = args[k + 1], 2;
    return 0;
  }

  void write() override {
    if (!formats_.built(static_cast<int>(values_.size()))) build_formats();
    const std::vector<Compute*> computes = check(true);
    // this rank's rows: every compute gives the same number
    const std::int64_t step = engine_.update->ntimestep;
    int nrows = -1;
    std::string first;
    for (std::size_t c = 0; c < values_.size(); ++c) {
      Compute* comp = computes[c];
      if (!comp) continue;
      if (comp->invoked_local != step) {
        comp->compute_local();
        comp->invoked_local = step;
      }
      if (nrows < 0) {
        nrows = comp->size_local_rows;
        first = values_[c].compute;
      }
      bool same = comp->size_local_rows == nrows;
      int all_same = same ? 1 : 0;
      MPI_Allreduce(MPI_IN_PLACE, &all_same, 1, MPI_INT, MPI_MIN, engine_.world);
      if (!all_same)
        throw RunError("dump " + id + ": computes " + first + " and " + values_[c].compute +
                       " give different numbers of local rows; one dump local writes rows of the same items");
    }
    if (nrows < 0) nrows = 0;  // index only: no rows
    const int ncols = static_cast<int>(values_.size());
    std::vector<double> local(static_cast<std::size_t>(nrows) * ncols, 0.0);
    for (int c = 0; c < ncols; ++c) {
      const Compute* comp = computes[c];
      if (!comp) continue;
      const int stride = std::max(1, comp->size_local_cols);
      const int col = values_[c].col > 0 ? values_[c].col - 1 : 0;
      for (int r = 0; r < nrows; ++r)
        local[static_cast<std::size_t>(r) * ncols + c] =
            comp->array_local[static_cast<std::size_t>(r) * stride + col];
    }
    std::vector<double> all;
    const std::int64_t total = dumpio::gather_rows(engine_.world, local, ncols, all);
    std::string err;
    if (engine_.rank == 0) {
      for (int c = 0; c < ncols; ++c)
        if (values_[c].index)
          for (std::int64_t r = 0; r < total; ++r)
            all[r * ncols + c] = static_cast<double>(r + 1);
      const std::string file = dumpio::expand(filename, step, pad_);
      if (multifile_) {
        err = replace_file(file, [&](std::FILE* fp) { write_frame(fp, all, total); });
      } else {
        if (!fp_) fp_ = std::fopen(file.c_str(), append_ ? "a" : "w");
        if (!fp_) {
          err = dumpio::open_error(file);
        } else {
          write_frame(fp_, all, total);
          if (std::ferror(fp_) != 0 || std::fflush(fp_) != 0) err = dumpio::open_error(file);
        }
      }
    }
    err = dumpio::first_error(engine_.world, err);
    if (!err.empty()) throw RunError("dump " + id + ": " + err);
  }

 private:
  /// The compute of each value (nullptr for index), or an InputError; with
  /// `columns` also checks the columns against the computes' current shape.
  std::vector<Compute*> check(bool columns) const {
    const std::string where = "dump " + id + " local";
    std::vector<Compute*> out;
    for (const LocalValue& v : values_) {
      if (v.index) {
        out.push_back(nullptr);
        continue;
      }
      Compute* c = engine_.modify->find_compute(v.compute);
      if (!c)
        throw InputError(where + ": '" + v.name + "': there is no compute '" + v.compute +
                         "'; define it before the dump");
      if (!c->local_flag)
        throw InputError(where + ": '" + v.name + "': compute " + v.compute + " (" + c->style +
                         ") gives no local values; dump custom writes per-atom values, thermo_style "
                         "global ones");
      if (columns) {
        if (v.col == 0 && c->size_local_cols > 0)
          throw InputError(where + ": compute " + v.compute + " gives a local array of " +
                           std::to_string(c->size_local_cols) + " columns; write its columns as c_" +
                           v.compute + "[1] ... c_" + v.compute + "[" + std::to_string(c->size_local_cols) +
                           "]");
        if (v.col > 0 && (c->size_local_cols == 0 || v.col > c->size_local_cols))
          throw InputError(where + ": '" + v.name + "': compute " + v.compute + " gives " +
                           (c->size_local_cols == 0
                                ? std::string("a local vector (write c_") + v.compute + ")"
                                : std::to_string(c->size_local_cols) + " columns"));
      }
      out.push_back(c);
    }
    return out;
  }

  void build_formats() {
    std::vector<bool> integer;
    for (const LocalValue& v : values_)
      integer.push_back(v.index);
    formats_.build(integer);
  }

  void write_frame(std::FILE* fp, const std::vector<double>& rows, std::int64_t nrows) const {
    std::string out;
    dumpio::append_frame_header(out, engine_, "ENTRIES", nrows);
    out += "ITEM: " + label_ + " " + columns_ + "\n";
    const int ncols = static_cast<int>(values_.size());
    std::vector<std::int64_t> order(nrows);
    std::iota(order.begin(), order.end(), 0);
    if (sort_ != 0) {
      const int key = std::abs(sort_) - 1;
      const bool descending = sort_ < 0;
      std::stable_sort(order.begin(), order.end(), [&](std::int64_t a, std::int64_t b) {
        const double ka = rows[a * ncols + key], kb = rows[b * ncols + key];
        return descending ? ka > kb : ka < kb;
      });
    }
    for (std::int64_t r : order) {
      formats_.append_row(out, rows.data() + r * ncols);
      if (out.size() > (1u << 20)) {
        std::fwrite(out.data(), 1, out.size(), fp);
        out.clear();
      }
    }
    std::fwrite(out.data(), 1, out.size(), fp);
  }

  std::vector<LocalValue> values_;
  std::string columns_;
  bool multifile_ = false, append_ = false;
  int pad_ = 0, sort_ = 0;
  std::string label_ = "ENTRIES";
  dumpio::ColumnFormats formats_;
  std::FILE* fp_ = nullptr;
};

}  // namespace

GRANARY_DUMP_STYLE("local", DumpLocal);

}  // namespace granary
