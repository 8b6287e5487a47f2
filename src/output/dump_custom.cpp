#include "output/dump_custom.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <numeric>

#include "compute/compute.h"
#include "core/atom_properties.h"
#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "core/modify.h"
#include "particles/particles.h"

namespace granary {

namespace {

// Built-in per-particle fields.
// "c_ID[3]" -> ref "ID", col "3"; col "" when there is no bracket.
void split_ref(const std::string& word, std::string& ref, std::string& col) {
  const std::string body = word.substr(2);
  const auto open = body.find('[');
  if (open == std::string::npos) {
    ref = body;
    col.clear();
    return;
  }
  if (body.back() != ']') throw InputError("field '" + word + "' has an unclosed '['");
  ref = body.substr(0, open);
  col = body.substr(open + 1, body.size() - open - 2);
}

}  // namespace

// ---------------------------------------------------------------- DumpFields

DumpFields::DumpFields(Engine& engine, const Args& words, const std::string& what)
    : engine_(engine), what_(what) {
  for (const auto& w : words) {
    DumpField f;
    f.name = w;
    if (const AtomProperty* prop = find_atom_property(w)) {
      f.property = prop;
      f.integer = prop->integer;
      fields.push_back(f);
      continue;
    }
    const std::string prefix = w.substr(0, 2);
    if (w.size() > 2 && (prefix == "c_" || prefix == "f_" || prefix == "v_")) {
      std::string col;
      split_ref(w, f.ref, col);
      if (f.ref.empty()) throw InputError(what_ + ": field '" + w + "' needs a name after '" + prefix + "'");
      f.source = prefix == "c_"   ? DumpField::kCompute
                 : prefix == "f_" ? DumpField::kFix
                                  : DumpField::kVariable;
      if (f.source == DumpField::kVariable && !col.empty()) {
        throw InputError(what_ + ": variable field '" + w + "' takes no column index");
      }
      if (col == "*") {
        int ncols = 0;
        if (f.source == DumpField::kCompute)
          ncols = engine_.modify->compute_or_error(f.ref, what_)->peratom_cols;
        else
          ncols = engine_.modify->fix_or_error(f.ref, what_)->peratom_cols;
        if (ncols <= 0)
          throw InputError(what_ + ": '" + w + "' needs a per-atom array; " + prefix + f.ref +
                           " has no columns");
        for (int i = 1; i <= ncols; ++i) {
          DumpField g = f;
          g.col = i;
          g.name = prefix + f.ref + "[" + std::to_string(i) + "]";
          fields.push_back(g);
        }
        continue;
      }
      if (!col.empty()) {
        const long long c = parse_int(col, "column index of " + w);
        // [0] is the per-atom vector itself (LIGGGHTS' f_Temp[0] of a property/atom)
        if (c < 0) throw InputError(what_ + ": column index of '" + w + "' must be >= 1 (or 0 for a vector)");
        f.col = static_cast<int>(c);
      }
      fields.push_back(f);
      continue;
    }
    const std::string hint = did_you_mean(w, atom_property_names());
    throw InputError(
        what_ + ": unknown field '" + w + "'" + (hint.empty() ? "" : "; " + hint) +
        " (fields: id type x y z vx vy vz fx fy fz omegax omegay omegaz tqx tqy tqz"
        " radius diameter mass density body xs xu ix ..., c_ID, c_ID[i], f_ID, f_ID[i], v_name)");
  }
}

int DumpFields::find(const std::string& name) const {
  for (std::size_t c = 0; c < fields.size(); ++c)
    if (fields[c].name == name) return static_cast<int>(c);
  return -1;
}

void DumpFields::init() {
  for (const auto& f : fields) {
    if (f.source == DumpField::kCompute || f.source == DumpField::kFix) {
      bool peratom = false;
      int ncols = 0;
      const char* kind = f.source == DumpField::kCompute ? "compute" : "fix";
      if (f.source == DumpField::kCompute) {
        Compute* c = engine_.modify->compute_or_error(f.ref, what_ + " field " + f.name);
        peratom = c->peratom_flag;
        ncols = c->peratom_cols;
        if (c->local_flag)
          throw InputError(what_ + ": compute " + f.ref + " (" + c->style +
                           ") gives local values, one row per contact, not per-atom values; write them with "
                           "dump local or dump local/gran/vtk");
      } else {
        Fix* x = engine_.modify->fix_or_error(f.ref, what_ + " field " + f.name);
        peratom = x->peratom_flag;
        ncols = x->peratom_cols;
      }
      if (!peratom) throw InputError(what_ + ": " + kind + " " + f.ref + " does not give per-atom values");
      if (f.col == 0 && ncols != 0) {
        throw InputError(what_ + ": " + kind + " " + f.ref + " gives a per-atom array; name a column, e.g. " +
                         f.name + "[1]");
      }
      if (f.col > 0 && f.col > ncols) {
        throw InputError(what_ + ": column " + std::to_string(f.col) + " of " +
                         f.name.substr(0, f.name.find('[')) + " is out of range (it has " +
                         std::to_string(ncols) + " columns)");
      }
    } else if (f.source == DumpField::kVariable) {
      Variables& vars = engine_.input->variables();
      if (!vars.find(f.ref)) throw InputError(what_ + ": variable '" + f.ref + "' does not exist");
      if (!vars.is_atom(f.ref))
        throw InputError(what_ + ": variable '" + f.ref + "' is not an atom-style variable");
    }
  }
}

void DumpFields::select(int groupbit, const std::string& region, std::vector<int>& out) const {
  const Particles& p = *engine_.particles;
  const Region* r = region.empty() ? nullptr : engine_.domain->region_or_error(region, what_ + " region");
  out.clear();
  out.reserve(p.nlocal);
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & groupbit)) continue;
    if (r && !r->match(p.x[i])) continue;
    out.push_back(i);
  }
}

void DumpFields::property_column(const AtomProperty& prop, const std::vector<int>& sel, int stride,
                                 double* out) const {
  for (std::size_t k = 0; k < sel.size(); ++k)
    out[k * stride] = prop.value(engine_, sel[k]);
}

void DumpFields::pack(const std::vector<int>& sel, bool with_id, std::vector<double>& out) {
  const int stride = ncols() + (with_id ? 1 : 0);
  out.assign(sel.size() * stride, 0.0);
  for (int c = 0; c < ncols(); ++c) {
    const DumpField& f = fields[c];
    if (f.source == DumpField::kCore) {
      property_column(*f.property, sel, stride, out.data() + c);
      continue;
    }
    if (f.source == DumpField::kCompute)
      engine_.compute_peratom(f.ref, f.col, scratch_);
    else if (f.source == DumpField::kFix)
      engine_.fix_peratom(f.ref, f.col, scratch_);
    else
      engine_.input->variables().compute_atom(f.ref, scratch_);
    scratch_.resize(engine_.particles->nlocal, 0.0);
    for (std::size_t k = 0; k < sel.size(); ++k)
      out[k * stride + c] = scratch_[sel[k]];
  }
  if (with_id) property_column(*find_atom_property("id"), sel, stride, out.data() + ncols());
}

// -------------------------------------------------------------------- dumpio

namespace dumpio {

std::int64_t gather_rows(MPI_Comm comm, const std::vector<double>& local, int ncols,
                         std::vector<double>& all) {
  int rank = 0, nprocs = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &nprocs);
  long long mine = static_cast<long long>(local.size()), total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_LONG_LONG, MPI_SUM, comm);
  if (total > INT_MAX) {
    throw RunError("dump: " + std::to_string(total) +
                   " values are too many to gather on one rank; "
                   "use dump custom/vtk, which writes one piece per rank");
  }
  const int count = static_cast<int>(mine);
  std::vector<int> counts(rank == 0 ? nprocs : 0), displs(rank == 0 ? nprocs : 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  if (rank == 0) {
    for (int r = 1; r < nprocs; ++r)
      displs[r] = displs[r - 1] + counts[r - 1];
    all.resize(static_cast<std::size_t>(total));
  }
  MPI_Gatherv(local.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, comm);
  return rank == 0 && ncols > 0 ? total / ncols : 0;
}

std::string expand(const std::string& pattern, std::int64_t step, int pad) {
  const auto star = pattern.find('*');
  if (star == std::string::npos) return pattern;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%0*lld", std::max(0, std::min(pad, 30)), static_cast<long long>(step));
  return pattern.substr(0, star) + buf + pattern.substr(star + 1);
}

int parse_pvd(MPI_Comm comm, const Args& args, std::size_t k, const std::string& where, bool legacy,
              std::string& path) {
  if (args[k] != "pvd" || k + 1 >= args.size()) return 0;
  const std::string& v = args[k + 1];
  if (v == "no" || v == "off" || v == "none") {
    path.clear();
    return 2;
  }
  if (legacy)
    throw InputError(where +
                     ": legacy .vtk files cannot be listed in a .pvd (ParaView reads XML files from a "
                     "collection); write XML frames or use 'pvd no'");
  if (v.size() < 5 || v.compare(v.size() - 4, 4, ".pvd") != 0)
    throw InputError(where + ": the collection file name must end in .pvd, got '" + v + "'");
  check_directory(comm, v, where);
  path = v;
  return 2;
}

void check_directory(MPI_Comm comm, const std::string& file, const std::string& what) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string reason;
  if (rank == 0) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(file).parent_path();
    std::error_code ec;
    if (file.empty() || file.back() == '/') {
      reason = "the file name is empty";
    } else if (!dir.empty() && !fs::exists(dir, ec)) {
      reason = "directory '" + dir.string() + "' does not exist (create it first, e.g. with mkdir)";
    } else if (!dir.empty() && !fs::is_directory(dir, ec)) {
      reason = "'" + dir.string() + "' is not a directory";
    } else if (::access(dir.empty() ? "." : dir.c_str(), W_OK) != 0) {
      reason = "directory '" + (dir.empty() ? std::string(".") : dir.string()) + "' is not writable";
    }
  }
  int len = static_cast<int>(reason.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, comm);
  reason.resize(len);
  if (len > 0) MPI_Bcast(reason.data(), len, MPI_CHAR, 0, comm);
  if (!reason.empty()) throw InputError(what + ": cannot write '" + file + "': " + reason);
}

std::string first_error(MPI_Comm comm, const std::string& local_error) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int mine = local_error.empty() ? INT_MAX : rank, first = INT_MAX;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == INT_MAX) return "";
  std::string msg = local_error;
  int len = static_cast<int>(msg.size());
  MPI_Bcast(&len, 1, MPI_INT, first, comm);
  msg.resize(len);
  MPI_Bcast(msg.data(), len, MPI_CHAR, first, comm);
  return msg;
}

std::string open_error(const std::string& file) {
  return "cannot write '" + file + "': " + std::strerror(errno);
}

void append_frame_header(std::string& out, const Engine& e, const char* count_item, std::int64_t nrows) {
  const Domain& d = *e.domain;
  char buf[256];
  std::snprintf(buf, sizeof buf, "ITEM: TIMESTEP\n%lld\nITEM: NUMBER OF %s\n%lld\nITEM: BOX BOUNDS",
                static_cast<long long>(e.update->ntimestep), count_item, static_cast<long long>(nrows));
  out += buf;
  for (int dim = 0; dim < 3; ++dim) {
    out += ' ';
    out += d.boundary[dim][0];
    out += d.boundary[dim][1];
  }
  out += '\n';
  for (int dim = 0; dim < 3; ++dim) {
    std::snprintf(buf, sizeof buf, "%-1.16e %-1.16e\n", d.boxlo[dim], d.boxhi[dim]);
    out += buf;
  }
}

// ---------------------------------------------------------------- ColumnFormats

void ColumnFormats::resize(int ncols) {
  if (ncols == ncols_ && static_cast<int>(col_format_.size()) == ncols) return;
  ncols_ = ncols;
  col_format_.assign(ncols, "");
  if (static_cast<int>(line_format_.size()) != ncols) line_format_.clear();
  formats_.clear();
}

ColumnFormats::Format ColumnFormats::parse(const std::string& text) {
  format_number(0.0, text);  // validates: exactly one numeric conversion
  Format f;
  std::size_t j = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') continue;
    if (i + 1 < text.size() && text[i + 1] == '%') {
      ++i;
      continue;
    }
    j = i + 1;
    while (j < text.size() && std::string("-+ #0123456789.").find(text[j]) != std::string::npos)
      ++j;
    break;
  }
  f.spec = text;
  f.integer = text[j] == 'd' || text[j] == 'i';
  if (f.integer) f.spec.insert(j, "ll");
  return f;
}

void ColumnFormats::build(const std::vector<bool>& integer) {
  const int n = static_cast<int>(integer.size());
  resize(n);
  formats_.assign(n, Format{});
  for (int c = 0; c < n; ++c) {
    std::string text;
    if (!col_format_[c].empty())
      text = col_format_[c];
    else if (integer[c] && !int_format_.empty())
      text = int_format_;
    else if (!integer[c] && !float_format_.empty())
      text = float_format_;
    else if (!line_format_.empty())
      text = line_format_[c];
    if (!text.empty()) {
      formats_[c] = parse(text);
      continue;
    }
    Format f;
    f.integer = integer[c];
    f.spec = integer[c] ? "%lld" : precision_ > 0 ? "%." + std::to_string(precision_) + "g" : "%g";
    formats_[c] = f;
  }
}

int ColumnFormats::modify_param(const Args& args, std::size_t k, const std::string& where) {
  const std::string& key = args[k];
  const bool has1 = k + 1 < args.size(), has2 = k + 2 < args.size();
  if (key == "format" && has1) {
    const std::string& v = args[k + 1];
    formats_.clear();
    if (v == "none") {
      line_format_.clear();
      int_format_.clear();
      float_format_.clear();
      col_format_.assign(ncols_, "");
      return 2;
    }
    if ((v == "line" || v == "int" || v == "float") && !has2)
      throw InputError(where + " " + v + " needs a format string");
    if (v == "int" || v == "float") {
      parse(args[k + 2]);
      (v == "int" ? int_format_ : float_format_) = args[k + 2];
      return 3;
    }
    const bool is_column = !v.empty() && std::all_of(v.begin(), v.end(), [](char ch) {
      return std::isdigit(static_cast<unsigned char>(ch));
    });
    if (is_column) {
      if (!has2) throw InputError(where + " " + v + " needs a format string");
      const long long c = parse_int(v, where);
      if (c < 1 || c > ncols_)
        throw InputError(where + ": column " + v + " is out of range 1.." + std::to_string(ncols_));
      parse(args[k + 2]);
      col_format_[c - 1] = args[k + 2];
      return 3;
    }
    // `format line "..."` or the older `format "..."`: one conversion per column
    const std::string& text = v == "line" ? args[k + 2] : v;
    std::vector<std::string> words;
    std::size_t pos = 0;
    while ((pos = text.find_first_not_of(" \t", pos)) != std::string::npos) {
      const std::size_t end = text.find_first_of(" \t", pos);
      words.push_back(text.substr(pos, end == std::string::npos ? std::string::npos : end - pos));
      pos = end;
    }
    if (static_cast<int>(words.size()) != ncols_) {
      throw InputError(where + ": the format line has " + std::to_string(words.size()) + " conversions for " +
                       std::to_string(ncols_) + " columns");
    }
    for (const auto& w : words)
      parse(w);
    line_format_ = words;
    return v == "line" ? 3 : 2;
  }
  if (key == "precision" && has1) {
    const long long n = parse_int(args[k + 1], where);
    if (n < 1 || n > 17) throw InputError(where + ": significant digits must be 1..17");
    precision_ = static_cast<int>(n);
    formats_.clear();
    return 2;
  }
  return 0;
}

void ColumnFormats::append_row(std::string& out, const double* row) const {
  char buf[1200];
  for (int c = 0; c < ncols_; ++c) {
    const Format& f = formats_[c];
    int len;
    if (f.integer) {
      const double v = std::round(row[c]);
      const long long iv = std::fabs(v) < 9.2e18 ? static_cast<long long>(v) : 0;
      len = std::snprintf(buf, sizeof buf, f.spec.c_str(), iv);
    } else {
      len = std::snprintf(buf, sizeof buf, f.spec.c_str(), row[c]);
    }
    if (c > 0) out += ' ';
    out.append(buf, std::min<int>(std::max(len, 0), sizeof buf - 1));
  }
  out += '\n';
}

}  // namespace dumpio

// ---------------------------------------------------------------- DumpCustom

DumpCustom::DumpCustom(Engine& engine, const Args& args)
    : Dump(engine, args),
      fields_(engine, Args(args.begin() + std::min<std::size_t>(5, args.size()), args.end()),
              "dump " + args[0]) {
  if (args.size() < 6) throw InputError("dump " + id + ": usage: dump ID group-ID custom N file field ...");
  if (filename.size() > 3 && filename.compare(filename.size() - 3, 3, ".gz") == 0) {
    throw InputError("dump " + id +
                     ": compressed text dumps (.gz) are not supported; use dump custom/vtk "
                     "(zlib-compressed by default) or compress the files afterwards");
  }
  if (filename.find('%') != std::string::npos) {
    throw InputError("dump " + id +
                     ": '%' (one file per rank) is not supported by dump custom; "
                     "the frames are gathered on one rank");
  }
  multifile_ = filename.find('*') != std::string::npos;
  dumpio::check_directory(engine.world, filename, "dump " + id);
  formats_.resize(fields_.ncols());
  columns_ = "";
  for (const auto& f : fields_.fields)
    columns_ += (columns_.empty() ? "" : " ") + f.name;
}

DumpCustom::~DumpCustom() {
  finish();
}

void DumpCustom::finish() {
  if (fp_) {
    std::fclose(fp_);
    fp_ = nullptr;
  }
}

void DumpCustom::build_formats() {
  std::vector<bool> integer;
  for (const auto& f : fields_.fields)
    integer.push_back(f.integer);
  formats_.build(integer);
}

int DumpCustom::modify_param(const Args& args, std::size_t k) {
  const std::string& key = args[k];
  const bool has1 = k + 1 < args.size();
  const std::string where = "dump_modify " + id + " " + key;
  if (key == "sort" && has1) {
    const std::string& v = args[k + 1];
    if (v == "off")
      sort_ = 0;
    else if (v == "id")
      sort_ = kSortId;
    else {
      const long long c = parse_int(v, where);
      if (c == 0 || std::llabs(c) > fields_.ncols()) {
        throw InputError(where + ": column must be id, off or +-1.." + std::to_string(fields_.ncols()));
      }
      sort_ = static_cast<int>(c);
    }
    return 2;
  }
  if (const int used = formats_.modify_param(args, k, where)) return used;
  if (key == "pad" && has1) {
    const long long n = parse_int(args[k + 1], where);
    if (n < 0 || n > 30) throw InputError(where + ": pad must be 0..30");
    pad_ = static_cast<int>(n);
    return 2;
  }
  if (key == "append" && has1) return append_ = parse_bool(args[k + 1], where), 2;
  if (key == "time" && has1) return time_flag_ = parse_bool(args[k + 1], where), 2;
  if (key == "units" && has1) return units_flag_ = parse_bool(args[k + 1], where), 2;
  if (key == "flush" && has1) return parse_bool(args[k + 1], where), 2;  // frames are always flushed
  if (key == "label" && has1) return label_ = args[k + 1], 2;
  if (const int used = parse_region(args, k, where)) return used;
  return 0;
}

void DumpCustom::init() {
  fields_.init();
  build_formats();
}

void DumpCustom::write_frame(std::FILE* fp, const std::vector<double>& rows, std::int64_t nrows, int stride) {
  const Domain& d = *engine_.domain;
  std::string out;
  char buf[1200];
  if (units_flag_ && !units_written_) {
    out += "ITEM: UNITS\n" + d.units + "\n";
    units_written_ = true;
  }
  if (time_flag_) {
    std::snprintf(buf, sizeof buf, "ITEM: TIME\n%.16g\n", engine_.update->time());
    out += buf;
  }
  dumpio::append_frame_header(out, engine_, "ATOMS", nrows);
  out += "ITEM: " + label_ + " " + columns_ + "\n";
  append_rows(fp, out, rows, nrows, stride);
}

void DumpCustom::append_rows(std::FILE* fp, std::string& out, const std::vector<double>& rows,
                             std::int64_t nrows, int stride) {
  std::vector<std::int64_t> order(nrows);
  std::iota(order.begin(), order.end(), 0);
  if (sort_ != 0) {
    const int key = sort_ == kSortId ? stride - 1 : std::abs(sort_) - 1;
    const bool descending = sort_ != kSortId && sort_ < 0;
    std::stable_sort(order.begin(), order.end(), [&](std::int64_t a, std::int64_t b) {
      const double ka = rows[a * stride + key], kb = rows[b * stride + key];
      return descending ? ka > kb : ka < kb;
    });
  }
  for (std::int64_t r : order) {
    formats_.append_row(out, rows.data() + r * stride);
    if (out.size() > (1u << 20)) {
      std::fwrite(out.data(), 1, out.size(), fp);
      out.clear();
    }
  }
  std::fwrite(out.data(), 1, out.size(), fp);
}

void DumpCustom::write() {
  if (!formats_.built(fields_.ncols())) build_formats();
  std::vector<int> sel;
  fields_.select(groupbit, region_, sel);
  const bool with_id = sort_ == kSortId;
  const int stride = fields_.ncols() + (with_id ? 1 : 0);
  std::vector<double> local, all;
  fields_.pack(sel, with_id, local);
  const std::int64_t nrows = dumpio::gather_rows(engine_.world, local, stride, all);

  std::string err;
  if (engine_.rank == 0) {
    const std::string file = dumpio::expand(filename, engine_.update->ntimestep, pad_);
    if (multifile_) {
      // one file per frame: written under a temporary name, then renamed
      units_written_ = false;
      err = replace_file(file, [&](std::FILE* fp) { write_frame(fp, all, nrows, stride); });
    } else {
      if (!fp_) fp_ = std::fopen(file.c_str(), append_ ? "a" : "w");
      if (!fp_) {
        err = dumpio::open_error(file);
      } else {
        write_frame(fp_, all, nrows, stride);
        if (std::ferror(fp_) != 0 || std::fflush(fp_) != 0) err = dumpio::open_error(file);
      }
    }
  }
  err = dumpio::first_error(engine_.world, err);
  if (!err.empty()) throw RunError("dump " + id + ": " + err);
}

GRANARY_DUMP_STYLE("custom", DumpCustom);

}  // namespace granary
