// fix ID group ave/correlate Nevery Nrepeat Nfreq value1 value2 ... keyword args ...
//
// Time correlations of global scalars (LAMMPS/LIGGGHTS syntax and semantics):
// the values are sampled every Nevery steps; each sample is paired with itself
// and with the Nrepeat - 1 samples before it, and C_ij(k Nevery) accumulates
// V_i(earlier) * V_j(later) for the pairs (i, j) that `type` selects. Every
// Nfreq steps the averages C_ij(k Nevery) = sum / count (times `prefactor`)
// are written to the file, Nrepeat rows of "index delta count C...". With
// `ave one` the sums restart after each output from the sample of that step
// (its C(0) counts in both outputs, as in LAMMPS); with `ave running` they
// never restart. Keywords: type auto|upper|lower|auto/upper|auto/lower|full,
// ave one|running, start S, prefactor P, file F, overwrite,
// title1/title2/title3 TEXT.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "fix/sampled_values.h"

namespace granary {

namespace {

const char* const kUsage =
    "fix ID group ave/correlate Nevery Nrepeat Nfreq value1 ... [type "
    "auto|upper|lower|auto/upper|auto/lower|full] "
    "[ave one|running] [start S] [prefactor P] [file F] [overwrite] [title1|title2|title3 TEXT]";

class FixAveCorrelate : public Fix {
 public:
  FixAveCorrelate(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string what = "fix ave/correlate";
    if (args.size() < 7)
      throw InputError(what + " needs Nevery, Nrepeat, Nfreq and a value; usage: " + kUsage);
    every_ = parse_int(args[3], what + " Nevery");
    nrepeat_ = parse_int(args[4], what + " Nrepeat");
    nfreq_ = parse_int(args[5], what + " Nfreq");
    if (every_ <= 0 || nrepeat_ <= 0 || nfreq_ <= 0)
      throw InputError(what + ": Nevery, Nrepeat and Nfreq must be positive (got " + args[3] + " " + args[4] +
                       " " + args[5] + ")");
    if (nfreq_ % every_ != 0)
      throw InputError(what + ": Nfreq (" + args[5] + ") must be a multiple of Nevery (" + args[3] + ")");
    std::size_t k = 6;
    for (; k < args.size(); ++k) {
      const std::string& w = args[k];
      if (w.rfind("c_", 0) != 0 && w.rfind("f_", 0) != 0 && w.rfind("v_", 0) != 0) break;
      values_.push_back(parse_sampled_value(w, what, kUsage));
    }
    if (values_.empty())
      throw InputError(what + " needs at least one value (c_ID, f_ID or v_name); usage: " + kUsage);
    std::string type = "auto";
    bool running = false, overwrite = false;
    for (; k < args.size(); ++k) {
      const std::string& key = args[k];
      if (key == "overwrite") {
        overwrite = true;
        continue;
      }
      if (k + 1 >= args.size())
        throw InputError(what + " keyword '" + key + "' needs a value; usage: " + kUsage);
      const std::string& val = args[++k];
      if (key == "type") {
        if (val != "auto" && val != "upper" && val != "lower" && val != "auto/upper" && val != "auto/lower" &&
            val != "full")
          throw InputError(what + " type must be auto, upper, lower, auto/upper, auto/lower or full, got '" +
                           val + "'");
        type = val;
      } else if (key == "ave") {
        if (val != "one" && val != "running")
          throw InputError(what + " ave must be one or running, got '" + val + "'");
        running = val == "running";
      } else if (key == "start") {
        start_ = parse_int(val, what + " start");
      } else if (key == "prefactor") {
        prefactor_ = parse_double(val, what + " prefactor");
      } else if (key == "file") {
        file_ = val;
      } else if (key == "title1") {
        title_[0] = val;
      } else if (key == "title2") {
        title_[1] = val;
      } else if (key == "title3") {
        title_[2] = val;
      } else {
        throw InputError("unknown " + what + " keyword '" + key + "'; usage: " + kUsage);
      }
    }
    if (!running && (nrepeat_ - 1) * every_ > nfreq_)
      throw InputError(what + ": with ave one, (Nrepeat-1)*Nevery (" +
                       std::to_string((nrepeat_ - 1) * every_) + ") must not exceed Nfreq (" + args[5] + ")");
    if (overwrite && !running) throw InputError(what + ": overwrite needs ave running");
    running_ = running;
    overwrite_ = overwrite;

    // the pairs (i, j): V_i at the earlier, V_j at the later sample, in LAMMPS' column order
    const int n = static_cast<int>(values_.size());
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const bool take = type == "full" || (type == "auto" && i == j) || (type == "upper" && i < j) ||
                          (type == "auto/upper" && i <= j);
        if (take) pairs_.push_back({i, j});
      }
    if (type == "lower" || type == "auto/lower") {
      for (int i = 0; i < n; ++i)
        for (int j = 0; j <= i; ++j)
          if (i != j || type == "auto/lower") pairs_.push_back({i, j});
    }
    if (pairs_.empty())
      throw InputError(what + ": type " + type + " of a single value correlates nothing; use type auto");
    samples_.assign(static_cast<std::size_t>(nrepeat_) * n, 0.0);
    count_.assign(static_cast<std::size_t>(nrepeat_), 0);
    corr_.assign(static_cast<std::size_t>(nrepeat_) * pairs_.size(), 0.0);

    if (!file_.empty()) {
      if (title_[0].empty()) title_[0] = "# Time-correlated data for fix " + id;
      if (title_[1].empty()) title_[1] = "# Timestep Number-of-time-windows";
      if (title_[2].empty()) {
        title_[2] = "# Index TimeDelta Ncount";
        for (const auto& pr : pairs_)
          title_[2] += " " + values_[pr.first].text + "*" + values_[pr.second].text;
      }
      header_ = title_[0] + "\n" + title_[1] + "\n" + title_[2] + "\n";
      fp_ = start_output_file(engine, file_, header_, !overwrite_, what);
    }
    nevery = 1;  // sampling steps are tracked here
    next_ = first_sample(engine.update->ntimestep);
  }

  unsigned hooks() const override { return END_OF_STEP; }
  bool end_of_step_due(std::int64_t step) const override { return step == next_; }

  void init() override {
    for (const SampledValue& v : values_)
      check_global_value(engine_, v, this, "fix ave/correlate " + id, "it needs an equal-style variable");
    if (next_ < engine_.update->ntimestep) next_ = first_sample(engine_.update->ntimestep);
  }

  // samples at the first step of a run too, like LAMMPS (when it is a sampling step)
  void setup() override { end_of_step(); }

  void end_of_step() override {
    const std::int64_t step = engine_.update->ntimestep;
    if (step != next_) return;
    next_ += every_;
    const int n = static_cast<int>(values_.size());
    last_ = (last_ + 1) % nrepeat_;
    for (int i = 0; i < n; ++i)
      samples_[static_cast<std::size_t>(last_) * n + i] = sample_global(engine_, values_[i]);
    if (stored_ < nrepeat_) ++stored_;
    accumulate();
    if (step % nfreq_ != 0) return;
    write(step);
    if (!running_) {
      // the next window starts from this sample
      std::fill(count_.begin(), count_.end(), 0);
      std::fill(corr_.begin(), corr_.end(), 0.0);
      stored_ = 1;
      accumulate();
    }
  }

 private:
  std::int64_t first_sample(std::int64_t now) const {
    std::int64_t s = std::max<std::int64_t>(now, start_);
    if (s % every_ != 0) s = (s / every_ + 1) * every_;
    return s;
  }

  // the newest sample with itself and each stored earlier one
  void accumulate() {
    const int n = static_cast<int>(values_.size());
    const std::size_t np = pairs_.size();
    const double* later = &samples_[static_cast<std::size_t>(last_) * n];
    for (long long k = 0; k < stored_; ++k) {
      const long long m = ((last_ - k) % nrepeat_ + nrepeat_) % nrepeat_;
      const double* earlier = &samples_[static_cast<std::size_t>(m) * n];
      ++count_[k];
      for (std::size_t p = 0; p < np; ++p)
        corr_[k * np + p] += earlier[pairs_[p].first] * later[pairs_[p].second];
    }
  }

  void write(std::int64_t step) {
    if (engine_.rank != 0 || file_.empty()) return;
    const std::size_t np = pairs_.size();
    std::string block = std::to_string(step) + " " + std::to_string(nrepeat_) + "\n";
    char buf[64];
    for (long long k = 0; k < nrepeat_; ++k) {
      block += std::to_string(k + 1) + " " + std::to_string(k * every_) + " " + std::to_string(count_[k]);
      for (std::size_t p = 0; p < np; ++p) {
        if (count_[k] > 0) {
          std::snprintf(buf, sizeof buf, " %g",
                        prefactor_ * corr_[k * np + p] / static_cast<double>(count_[k]));
          block += buf;
        } else {
          block += " 0.0";
        }
      }
      block += "\n";
    }
    write_output_block(file_, header_, block, overwrite_, fp_, "fix ave/correlate");
  }

  long long every_ = 1, nrepeat_ = 1, nfreq_ = 1, start_ = 0;
  double prefactor_ = 1.0;
  bool running_ = false, overwrite_ = false;
  std::vector<SampledValue> values_;
  std::vector<std::pair<int, int>> pairs_;
  std::string file_, title_[3], header_;
  OutputFile fp_;  // rank 0, with a file and without overwrite

  std::int64_t next_ = 0;             // next sampling step
  long long last_ = -1, stored_ = 0;  // slot of the newest sample, samples stored (<= Nrepeat)
  std::vector<double> samples_;       // Nrepeat x values, a ring
  std::vector<long long> count_;      // per delay
  std::vector<double> corr_;          // per delay x pair
};

}  // namespace

GRANARY_FIX_STYLE("ave/correlate", FixAveCorrelate);

}  // namespace granary
