// fix ID group ave/time Nevery Nrepeat Nfreq value1 value2 ... keyword args ...
//
// Time averages of global scalars (LAMMPS syntax and semantics, scalar mode):
// every Nfreq steps the fix outputs the average of Nrepeat samples of each
// value taken Nevery steps apart and ending on the output step, i.e. at steps
// Nfreq - (Nrepeat-1)*Nevery, ..., Nfreq - Nevery, Nfreq (and the same in
// every later Nfreq window). Values: c_ID (scalar of a compute), c_ID[i]
// (element i of its global vector), f_ID, f_ID[i] (fix outputs), v_name
// (equal-style variable). Keywords:
//   mode scalar|vector          scalar: each value one global number;
//                               vector: each value a global vector (c_ID,
//                               f_ID) or array column (c_ID[i]) of one
//                               length, averaged element by element (e.g.
//                               compute rdf); written as blocks of rows
//   ave one|running|window M    what each output holds: the last Nfreq
//                               average, the average of all Nfreq averages
//                               so far, or of the last M of them
//   start S                     no samples before step S
//   file F                      one line per output: "step v1 v2 ..."
//   title1/title2/title3 STRING header lines of the file
//   format F                    C format of each value in the file (default " %g")
// Outputs (mode scalar): one value -> global scalar f_ID; several -> global
// vector f_ID[i]. Before the first output the outputs are 0. Mode vector has
// no global outputs (its averages go to the file).
#include <mpi.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <sstream>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "compute/compute.h"
#include "fix/fix.h"
#include "fix/sampled_values.h"
#include "core/modify.h"

namespace granary {

namespace {

class FixAveTime : public Fix {
 public:
  FixAveTime(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group ave/time Nevery Nrepeat Nfreq value1 ... [mode scalar|vector] [ave one|running|window "
        "M] "
        "[start S] [file F] [format F] [title1|title2|title3 TEXT]";
    if (args.size() < 7)
      throw InputError("fix ave/time needs Nevery, Nrepeat, Nfreq and a value; usage: " + usage);
    every_ = parse_int(args[3], "fix ave/time Nevery");
    nrepeat_ = parse_int(args[4], "fix ave/time Nrepeat");
    nfreq_ = parse_int(args[5], "fix ave/time Nfreq");
    // the conditions LAMMPS states for the three numbers
    if (every_ <= 0 || nrepeat_ <= 0 || nfreq_ <= 0)
      throw InputError("fix ave/time: Nevery, Nrepeat and Nfreq must be positive (got " + args[3] + " " +
                       args[4] + " " + args[5] + ")");
    if (nfreq_ % every_ != 0)
      throw InputError("fix ave/time: Nfreq (" + args[5] + ") must be a multiple of Nevery (" + args[3] +
                       ")");
    if (nrepeat_ * every_ > nfreq_)
      throw InputError("fix ave/time: Nrepeat*Nevery (" + std::to_string(nrepeat_ * every_) +
                       ") must not exceed Nfreq (" + args[5] + ")");

    std::size_t k = 6;
    for (; k < args.size(); ++k) {
      const std::string& w = args[k];
      if (w.rfind("c_", 0) != 0 && w.rfind("f_", 0) != 0 && w.rfind("v_", 0) != 0) break;
      values_.push_back(parse_value(w));
    }
    if (values_.empty())
      throw InputError("fix ave/time needs at least one value (c_ID, f_ID or v_name); usage: " + usage);

    for (; k < args.size(); k += 2) {
      const std::string& key = args[k];
      if (k + 1 >= args.size())
        throw InputError("fix ave/time keyword '" + key + "' needs a value; usage: " + usage);
      const std::string& val = args[k + 1];
      if (key == "mode") {
        if (val != "scalar" && val != "vector")
          throw InputError("fix ave/time mode must be scalar or vector (got '" + val + "')");
        vector_mode_ = val == "vector";
      } else if (key == "ave") {
        std::size_t at = k + 1;
        ave_ = static_cast<Ave>(parse_ave_keyword(args, at, "fix ave/time", window_));
        k = at - 1;
      } else if (key == "start") {
        start_ = parse_int(val, "fix ave/time start");
      } else if (key == "file") {
        file_ = val;
      } else if (key == "format") {
        // one floating-point conversion, nothing else that printf would read
        int conversions = 0;
        for (std::size_t c = 0; c < val.size(); ++c) {
          if (val[c] != '%') continue;
          if (c + 1 < val.size() && val[c + 1] == '%') {
            ++c;
            continue;
          }
          const auto end = val.find_first_not_of("0123456789.-+ #", c + 1);
          if (end == std::string::npos || std::string("eEfgG").find(val[end]) == std::string::npos)
            throw InputError("fix ave/time format '" + val + "' must use one %e, %f or %g conversion");
          ++conversions;
        }
        if (conversions != 1)
          throw InputError("fix ave/time format '" + val +
                           "' must contain exactly one %e, %f or %g conversion");
        format_ = val;
      } else if (key == "title1") {
        title1_ = val;
      } else if (key == "title2") {
        title2_ = val;
      } else if (key == "title3") {
        title3_ = val;
      } else {
        throw InputError("unknown fix ave/time keyword '" + key + "'; usage: " + usage);
      }
    }

    const int n = static_cast<int>(values_.size());
    if (vector_mode_) {
      for (const SampledValue& v : values_)
        if (v.kind == 'v')
          throw InputError("fix ave/time mode vector: '" + v.text +
                           "' is a variable; mode vector averages global vectors (c_ID, f_ID) and array "
                           "columns (c_ID[i])");
    } else if (n == 1) {
      scalar_flag = true;
    } else {
      size_vector = n;
    }
    sum_.assign(vector_mode_ ? 0 : n, 0.0);
    out_.assign(vector_mode_ ? 0 : n, 0.0);
    total_.assign(vector_mode_ ? 0 : n, 0.0);
    nevery = 1;  // sampling steps are tracked here (schedule_)
    restart_global = true;

    if (!file_.empty()) {
      if (title1_.empty()) title1_ = "# Time-averaged data for fix " + id;
      if (title2_.empty()) {
        title2_ = vector_mode_ ? "# TimeStep Number-of-rows" : "# TimeStep";
        if (!vector_mode_)
          for (const SampledValue& v : values_)
            title2_ += " " + v.text;
      }
      if (vector_mode_ && title3_.empty()) {
        title3_ = "# Row";
        for (const SampledValue& v : values_)
          title3_ += " " + v.text;
      }
      std::string header = title1_ + "\n" + title2_ + "\n";
      if (!title3_.empty()) header += title3_ + "\n";
      fp_ = start_output_file(engine, file_, header, true, "fix ave/time");
    }
    schedule_.set(every_, nrepeat_, nfreq_, start_);
    schedule_.begin(engine.update->ntimestep);
  }

  unsigned hooks() const override { return END_OF_STEP; }
  bool end_of_step_due(std::int64_t step) const override { return schedule_.due(step); }

  void init() override {
    for (const SampledValue& v : values_) {
      if (vector_mode_)
        check_vector_value(v);
      else
        check_global_value(engine_, v, this, "fix ave/time " + id, "it needs an equal-style variable");
    }
    schedule_.catch_up(engine_.update->ntimestep);
  }

  // samples at the first step of a run too, like LAMMPS (when it is a sampling step)
  void setup() override { end_of_step(); }

  void end_of_step() override {
    const std::int64_t step = engine_.update->ntimestep;
    if (!schedule_.due(step)) return;
    const std::vector<double> x = sample();
    if (sum_.size() != x.size()) {
      // mode vector: the length is known at the first sample and may not change
      if (!sum_.empty())
        throw RunError("fix ave/time " + id + ": the vectors changed length from " +
                       std::to_string(sum_.size() / values_.size()) + " to " +
                       std::to_string(x.size() / values_.size()) + " rows");
      sum_.assign(x.size(), 0.0);
      out_.assign(x.size(), 0.0);
      total_.assign(x.size(), 0.0);
    }
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (schedule_.window_start()) sum_[i] = 0.0;
      sum_[i] += x[i];
    }
    if (!schedule_.sampled(step)) return;
    // an output step: the average of the Nrepeat samples
    const int n = static_cast<int>(x.size());
    std::vector<double> avg(n);
    for (int i = 0; i < n; ++i)
      avg[i] = sum_[i] / static_cast<double>(nrepeat_);
    if (ave_ == ONE) {
      out_ = avg;
    } else if (ave_ == RUNNING) {
      ++count_;
      for (int i = 0; i < n; ++i) {
        total_[i] += avg[i];
        out_[i] = total_[i] / static_cast<double>(count_);
      }
    } else {
      window_values_.push_back(avg);
      if (static_cast<long long>(window_values_.size()) > window_) window_values_.pop_front();
      for (int i = 0; i < n; ++i) {
        double s = 0.0;
        for (const auto& w : window_values_)
          s += w[i];
        out_[i] = s / static_cast<double>(window_values_.size());
      }
    }
    if (fp_ && vector_mode_) {
      // "step rows", then one line per row: "row v1 v2 ..." (rows from 1)
      const std::size_t nv = values_.size(), rows = out_.size() / nv;
      std::fprintf(fp_.get(), "%lld %zu\n", static_cast<long long>(step), rows);
      for (std::size_t r = 0; r < rows; ++r) {
        std::fprintf(fp_.get(), "%zu", r + 1);
        for (std::size_t v = 0; v < nv; ++v)
          std::fprintf(fp_.get(), format_.c_str(), out_[r * nv + v]);
        std::fprintf(fp_.get(), "\n");
      }
      std::fflush(fp_.get());
    } else if (fp_) {
      std::fprintf(fp_.get(), "%lld", static_cast<long long>(step));
      for (int i = 0; i < n; ++i)
        std::fprintf(fp_.get(), format_.c_str(), out_[i]);
      std::fprintf(fp_.get(), "\n");
      std::fflush(fp_.get());
    }
  }

  double compute_scalar() override { return out_[0]; }
  double compute_vector(int i) override { return out_[i]; }

  // The running sums and the last outputs (ave running / window continue across restarts).
  void pack_restart(std::string& out) const override {
    std::ostringstream os;
    os.precision(17);
    os << out_.size() << ' ' << count_;
    for (std::size_t i = 0; i < out_.size(); ++i)
      os << ' ' << total_[i] << ' ' << out_[i];
    os << ' ' << window_values_.size();
    for (const auto& w : window_values_)
      for (double x : w)
        os << ' ' << x;
    out = os.str();
  }

  void unpack_restart(const std::string& in) override {
    std::istringstream is(in);
    std::size_t n = 0, nw = 0;
    long long count = 0;
    if (!(is >> n >> count) || n == 0 || (!vector_mode_ && n != values_.size()) || n % values_.size() != 0)
      return;  // other values: start afresh
    std::vector<double> total(n), out(n);
    for (std::size_t i = 0; i < n; ++i)
      is >> total[i] >> out[i];
    std::deque<std::vector<double>> window;
    if (is >> nw) {
      for (std::size_t k = 0; k < nw; ++k) {
        std::vector<double> w(n);
        for (double& x : w)
          is >> x;
        window.push_back(w);
      }
    }
    if (!is) return;
    count_ = count;
    total_ = total;
    out_ = out;
    if (sum_.size() != n) sum_.assign(n, 0.0);
    window_values_ = window;
  }

 private:
  enum Ave { ONE, RUNNING, WINDOW };
  static SampledValue parse_value(const std::string& w) {
    SampledValue v;
    v.kind = w[0];
    v.text = w;
    std::string name = w.substr(2);
    const auto lb = name.find('[');
    if (lb != std::string::npos) {
      if (name.back() != ']' || v.kind == 'v')
        throw InputError("fix ave/time value '" + w +
                         "' is malformed; use c_ID, c_ID[i], f_ID, f_ID[i] or v_name");
      v.col = static_cast<int>(parse_int(name.substr(lb + 1, name.size() - lb - 2), "index of " + w));
      if (v.col < 1) throw InputError("fix ave/time value '" + w + "': the index must be >= 1");
      name = name.substr(0, lb);
    }
    if (name.empty()) throw InputError("fix ave/time value '" + w + "' has no name");
    v.id = name;
    return v;
  }

  /// One sample of every value: mode scalar, one number each; mode vector,
  /// the vectors (all of one length L), row-major: [row * nvalues + value].
  std::vector<double> sample() {
    const std::size_t nv = values_.size();
    if (!vector_mode_) {
      std::vector<double> x(nv);
      for (std::size_t i = 0; i < nv; ++i)
        x[i] = sample_global(engine_, values_[i]);
      return x;
    }
    std::vector<std::vector<double>> cols(nv);
    for (std::size_t i = 0; i < nv; ++i) {
      cols[i] = vector_of(values_[i]);
      if (cols[i].size() != cols[0].size())
        throw RunError("fix ave/time " + id + " mode vector: '" + values_[i].text + "' has " +
                       std::to_string(cols[i].size()) + " rows, '" + values_[0].text + "' " +
                       std::to_string(cols[0].size()) + "; the values must have the same length");
    }
    std::vector<double> x(cols[0].size() * nv);
    for (std::size_t r = 0; r < cols[0].size(); ++r)
      for (std::size_t i = 0; i < nv; ++i)
        x[r * nv + i] = cols[i][r];
    return x;
  }

  /// Mode vector: c_ID / f_ID must give a global vector, c_ID[i] a global
  /// array with at least i columns.
  void check_vector_value(const SampledValue& v) const {
    const std::string what = "fix ave/time " + id + " mode vector: '" + v.text + "'";
    if (v.kind == 'c') {
      Compute* c = engine_.modify->compute_or_error(v.id, what);
      if (v.col == 0 && c->size_vector == 0)
        throw InputError(what + ": compute " + v.id + " gives no global vector");
      if (v.col > 0 && v.col > c->size_array_cols)
        throw InputError(what + ": compute " + v.id + " gives no global array with " + std::to_string(v.col) +
                         " columns (" + std::to_string(c->size_array_cols) + ")");
    } else {
      Fix* f = engine_.modify->fix_or_error(v.id, what);
      if (f == this) throw InputError(what + ": a fix cannot average its own output");
      if (v.col > 0) throw InputError(what + ": fixes give no global arrays; use f_" + v.id);
      if (f->size_vector == 0) throw InputError(what + ": fix " + v.id + " gives no global vector");
    }
  }

  std::vector<double> vector_of(const SampledValue& v) {
    const std::int64_t step = engine_.update->ntimestep;
    std::vector<double> out;
    if (v.kind == 'f') {
      Fix* f = engine_.modify->fix_or_error(v.id, "fix ave/time " + id);
      for (int i = 0; i < f->size_vector; ++i)
        out.push_back(f->compute_vector(i));
      return out;
    }
    Compute* c = engine_.modify->compute_or_error(v.id, "fix ave/time " + id);
    if (v.col == 0) {
      if (c->invoked_vector != step) {
        c->compute_vector();
        c->invoked_vector = step;
      }
      return c->vector;
    }
    if (c->invoked_array != step) {
      c->compute_array();
      c->invoked_array = step;
    }
    const int ncol = c->size_array_cols;
    for (int r = 0; r < c->size_array_rows; ++r)
      out.push_back(c->array[static_cast<std::size_t>(r) * ncol + (v.col - 1)]);
    return out;
  }

  bool vector_mode_ = false;
  long long every_ = 1, nrepeat_ = 1, nfreq_ = 1;
  std::vector<SampledValue> values_;
  Ave ave_ = ONE;
  long long window_ = 0;
  long long start_ = 0;
  std::string format_ = " %g";
  std::string file_, title1_, title2_, title3_;
  OutputFile fp_;  // rank 0, with a file

  SamplingSchedule schedule_;
  long long count_ = 0;  // Nfreq averages in the running average
  std::vector<double> sum_, out_, total_;
  std::deque<std::vector<double>> window_values_;
};

}  // namespace

GRANARY_FIX_STYLE("ave/time", FixAveTime);

}  // namespace granary
