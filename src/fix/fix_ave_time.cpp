// fix ID group ave/time Nevery Nrepeat Nfreq value1 value2 ... keyword args ...
//
// Time averages of global scalars (LAMMPS syntax and semantics, scalar mode):
// every Nfreq steps the fix outputs the average of Nrepeat samples of each
// value taken Nevery steps apart and ending on the output step, i.e. at steps
// Nfreq - (Nrepeat-1)*Nevery, ..., Nfreq - Nevery, Nfreq (and the same in
// every later Nfreq window). Values: c_ID (scalar of a compute), c_ID[i]
// (element i of its global vector), f_ID, f_ID[i] (fix outputs), v_name
// (equal-style variable). Keywords:
//   mode scalar                 (the only mode)
//   ave one|running|window M    what each output holds: the last Nfreq
//                               average, the average of all Nfreq averages
//                               so far, or of the last M of them
//   start S                     no samples before step S
//   file F                      one line per output: "step v1 v2 ..."
//   title1/title2/title3 STRING header lines of the file
//   format F                    C format of each value in the file (default " %g")
// Outputs: one value -> global scalar f_ID; several -> global vector f_ID[i].
// Before the first output the outputs are 0.
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
#include "fix/fix.h"
#include "fix/sampled_values.h"
#include "core/modify.h"

namespace granary {

namespace {

class FixAveTime : public Fix {
 public:
  FixAveTime(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group ave/time Nevery Nrepeat Nfreq value1 ... [mode scalar] [ave one|running|window M] "
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
        if (val == "vector")
          throw InputError(
              "fix ave/time mode vector is not supported; average vector elements c_ID[i] in mode scalar");
        if (val != "scalar") throw InputError("fix ave/time mode must be scalar (got '" + val + "')");
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
    if (n == 1)
      scalar_flag = true;
    else
      size_vector = n;
    sum_.assign(n, 0.0);
    out_.assign(n, 0.0);
    total_.assign(n, 0.0);
    nevery = 1;  // sampling steps are tracked here (schedule_)
    restart_global = true;

    if (!file_.empty()) {
      if (title1_.empty()) title1_ = "# Time-averaged data for fix " + id;
      if (title2_.empty()) {
        title2_ = "# TimeStep";
        for (const SampledValue& v : values_)
          title2_ += " " + v.text;
      }
      std::string header = title1_ + "\n" + title2_ + "\n";
      if (!title3_.empty()) header += title3_ + "\n";
      fp_ = start_output_file(engine, file_, header, true, "fix ave/time");
    }
    schedule_.set(every_, nrepeat_, nfreq_, start_);
    schedule_.begin(engine.update->ntimestep);
  }

  unsigned hooks() const override { return END_OF_STEP; }

  void init() override {
    for (const SampledValue& v : values_)
      check_global_value(engine_, v, this, "fix ave/time " + id, "it needs an equal-style variable");
    schedule_.catch_up(engine_.update->ntimestep);
  }

  // samples at the first step of a run too, like LAMMPS (when it is a sampling step)
  void setup() override { end_of_step(); }

  void end_of_step() override {
    const std::int64_t step = engine_.update->ntimestep;
    if (!schedule_.due(step)) return;
    for (std::size_t i = 0; i < values_.size(); ++i) {
      const double x = sample_global(engine_, values_[i]);
      if (schedule_.window_start()) sum_[i] = 0.0;
      sum_[i] += x;
    }
    if (!schedule_.sampled(step)) return;
    // an output step: the average of the Nrepeat samples
    const int n = static_cast<int>(values_.size());
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
    if (fp_) {
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
    os << values_.size() << ' ' << count_;
    for (std::size_t i = 0; i < values_.size(); ++i)
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
    if (!(is >> n >> count) || n != values_.size()) return;  // other values: start afresh
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
