// fix ID group ave/histo Nevery Nrepeat Nfreq lo hi Nbin value1 ... keyword args ...
//
// Histograms of sampled values, averaged over time (LIGGGHTS/LAMMPS syntax):
// every Nfreq steps the fix forms the average of the Nrepeat histograms of
// the samples taken Nevery steps apart and ending on that step, then
// combines it with earlier ones (ave one / running / window M).
// mode scalar: global values (c_ID, c_ID[i], f_ID, f_ID[i], v_name of an
//   equal-style variable), one value each per sample.
// mode vector: per-atom values (x y z vx vy vz fx fy fz, c_ID / f_ID per-atom
//   vectors or columns c_ID[i] / f_ID[i], or all columns of an array,
//   v_name atom-style) of the particles of the group.
// Bins: Nbin of equal width between lo and hi; a value on the boundary of two
// bins goes to the lower one. beyond ignore: values outside [lo, hi] are not
// binned (counted as missing); end: they go to the first or last bin; extra:
// two more bins (coordinates lo and hi) hold them.
// Outputs: global vector f_ID[1..4] = total count, missing count, smallest
// and largest value (also of values not binned); with `file`, one block per
// output: "step nbins total missing min max", then "bin coord count
// count/total" per bin.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "fix/fix.h"
#include "fix/sampled_values.h"
#include "particles/particles.h"

namespace granary {

namespace {

const std::string kUsage =
    "fix ID group ave/histo Nevery Nrepeat Nfreq lo hi Nbin value1 ... [mode scalar|vector] [file F] "
    "[ave one|running|window M] [start S] [beyond ignore|end|extra] [overwrite] [title1|title2|title3 TEXT]";

constexpr double kInf = std::numeric_limits<double>::infinity();

class FixAveHisto : public Fix {
 public:
  FixAveHisto(Engine& engine, const Args& args) : Fix(engine, args) {
    what_ = "fix " + id + " (ave/histo)";
    if (args.size() < 10)
      throw InputError(what_ + " needs Nevery, Nrepeat, Nfreq, lo, hi, Nbin and a value; usage: " + kUsage);
    parse_schedule(&args[3], what_, every_, nrepeat_, nfreq_);
    lo_ = parse_double(args[6], what_ + " lo");
    hi_ = parse_double(args[7], what_ + " hi");
    nbins_ = static_cast<int>(parse_int(args[8], what_ + " Nbin"));
    if (!(hi_ > lo_))
      throw InputError(what_ + ": hi (" + args[7] + ") must be larger than lo (" + args[6] + ")");
    if (nbins_ < 1)
      throw InputError(what_ + ": Nbin must be a positive number of bins (got " + args[8] + ")");

    static const std::vector<std::string> kKeywords = {"mode",   "file",   "ave",    "start",    "beyond",
                                                       "title1", "title2", "title3", "overwrite"};
    std::size_t k = 9;
    for (; k < args.size(); ++k) {
      if (std::find(kKeywords.begin(), kKeywords.end(), args[k]) != kKeywords.end()) break;
      values_.push_back(parse_sampled_value(args[k], what_, kUsage));
    }
    if (values_.empty()) throw InputError(what_ + " needs at least one value; usage: " + kUsage);
    bool overwrite = false;
    for (; k < args.size(); ++k) {
      const std::string& key = args[k];
      if (key == "overwrite") {
        overwrite = true;
        continue;
      }
      if (k + 1 >= args.size())
        throw InputError(what_ + ": keyword '" + key + "' needs a value; usage: " + kUsage);
      const std::string& val = args[++k];
      if (key == "mode") {
        if (val != "scalar" && val != "vector")
          throw InputError(what_ + ": mode must be scalar or vector (got '" + val + "')");
        vector_mode_ = val == "vector";
      } else if (key == "file") {
        file_ = val;
      } else if (key == "ave") {
        ave_ = static_cast<Ave>(parse_ave_keyword(args, k, what_, window_));
      } else if (key == "start") {
        start_ = parse_int(val, what_ + " start");
      } else if (key == "beyond") {
        if (val == "ignore")
          beyond_ = IGNORE;
        else if (val == "end")
          beyond_ = END;
        else if (val == "extra")
          beyond_ = EXTRA;
        else
          throw InputError(what_ + ": beyond must be ignore, end or extra (got '" + val + "')");
      } else if (key == "title1") {
        title1_ = val;
      } else if (key == "title2") {
        title2_ = val;
      } else if (key == "title3") {
        title3_ = val;
      } else {
        throw InputError(what_ + ": unknown keyword '" + key + "'; usage: " + kUsage);
      }
    }
    if (overwrite && ave_ != RUNNING)
      throw InputError(what_ + ": overwrite needs ave running (as in LIGGGHTS)");
    overwrite_ = overwrite;
    for (const SampledValue& v : values_) {
      if (!vector_mode_ && v.kind == 'a')
        throw InputError(what_ + ": " + v.text + " is a per-atom value; it needs mode vector");
    }

    if (beyond_ == EXTRA) nbins_ += 2;
    binsize_ = (hi_ - lo_) / static_cast<double>(beyond_ == EXTRA ? nbins_ - 2 : nbins_);
    coord_.resize(nbins_);
    for (int b = 0; b < nbins_; ++b) {
      if (beyond_ == EXTRA)
        coord_[b] = b == 0 ? lo_ : b == nbins_ - 1 ? hi_ : lo_ + (b - 0.5) * binsize_;
      else
        coord_[b] = lo_ + (b + 0.5) * binsize_;
    }
    sum_.assign(nbins_, 0.0);
    out_.assign(nbins_, 0.0);
    size_vector = 4;
    nevery = 1;  // sampling steps are tracked here (schedule_)

    if (!file_.empty()) {
      if (title1_.empty()) title1_ = "# Histogram for fix " + id;
      if (title2_.empty())
        title2_ = "# TimeStep Number-of-bins Total-counts Missing-counts Min-value Max-value";
      if (title3_.empty()) title3_ = "# Bin Coord Count Count/Total";
      header_ = title1_ + "\n" + title2_ + "\n" + title3_ + "\n";
      fp_ = start_output_file(engine, file_, header_, !overwrite_, what_);
    }
    schedule_.set(every_, nrepeat_, nfreq_, start_);
    schedule_.begin(engine.update->ntimestep);
  }

  unsigned hooks() const override { return END_OF_STEP; }
  bool end_of_step_due(std::int64_t step) const override { return schedule_.due(step); }

  void init() override {
    for (const SampledValue& v : values_) {
      if (vector_mode_) {
        check_peratom_value_or_array(v);
      } else {
        check_global_value(engine_, v, this, what_,
                           "it needs mode vector (mode scalar takes equal-style variables)");
      }
    }
    schedule_.catch_up(engine_.update->ntimestep);
  }

  void setup() override { end_of_step(); }

  void end_of_step() override {
    const std::int64_t step = engine_.update->ntimestep;
    if (!schedule_.due(step)) return;
    if (schedule_.window_start()) {
      std::fill(sum_.begin(), sum_.end(), 0.0);
      count_ = missing_ = 0.0;
      min_ = kInf;
      max_ = -kInf;
    }
    // this sample's histogram (all ranks' particles in mode vector)
    std::vector<double> h(nbins_ + 2, 0.0);  // bins, then count and missing
    double lohi[2] = {kInf, kInf};           // min, -max
    if (vector_mode_) {
      const Particles& p = *engine_.particles;
      for (const SampledValue& v : values_) {
        const int cols = v.kind == 'a' || v.kind == 'v' || v.col > 0 ? 0 : peratom_columns(engine_, v);
        for (int c = cols == 0 ? 0 : 1; c <= cols; ++c) {
          SampledValue one = v;
          if (cols > 0) one.col = c;
          sample_peratom(engine_, one, scratch_);
          for (int i = 0; i < p.nlocal; ++i)
            if (p.mask[i] & groupbit) bin(scratch_[i], h, lohi);
        }
      }
      std::vector<double> all(h.size());
      MPI_Allreduce(h.data(), all.data(), static_cast<int>(h.size()), MPI_DOUBLE, MPI_SUM, engine_.world);
      h.swap(all);
      double lohi_all[2];
      MPI_Allreduce(lohi, lohi_all, 2, MPI_DOUBLE, MPI_MIN, engine_.world);
      lohi[0] = lohi_all[0];
      lohi[1] = lohi_all[1];
    } else {
      for (const SampledValue& v : values_)
        bin(sample_global(engine_, v), h, lohi);
    }
    for (int b = 0; b < nbins_; ++b)
      sum_[b] += h[b];
    count_ += h[nbins_];
    missing_ += h[nbins_ + 1];
    min_ = std::min(min_, lohi[0]);
    max_ = std::max(max_, -lohi[1]);

    if (!schedule_.sampled(step)) return;
    // an output step: the average of the Nrepeat histograms, combined with earlier ones
    Histogram now;
    now.bins.resize(nbins_);
    const double inv = 1.0 / static_cast<double>(nrepeat_);
    for (int b = 0; b < nbins_; ++b)
      now.bins[b] = sum_[b] * inv;
    now.count = count_ * inv;
    now.missing = missing_ * inv;
    now.min = min_;
    now.max = max_;
    if (ave_ == ONE) history_.clear();
    history_.push_back(now);
    if (ave_ == WINDOW && static_cast<long long>(history_.size()) > window_) history_.pop_front();
    if (ave_ == RUNNING && history_.size() > 1) {
      // keep the running sum as one entry, weighted by the number of outputs
      Histogram& total = history_.front();
      for (int b = 0; b < nbins_; ++b)
        total.bins[b] += now.bins[b];
      total.count += now.count;
      total.missing += now.missing;
      total.min = std::min(total.min, now.min);
      total.max = std::max(total.max, now.max);
      history_.pop_back();
    }
    const double n =
        ave_ == RUNNING ? static_cast<double>(++noutputs_) : static_cast<double>(history_.size());
    std::fill(out_.begin(), out_.end(), 0.0);
    stats_[0] = stats_[1] = 0.0;
    stats_[2] = kInf;
    stats_[3] = -kInf;
    for (const Histogram& e : history_) {
      for (int b = 0; b < nbins_; ++b)
        out_[b] += e.bins[b] / n;
      stats_[0] += e.count / n;
      stats_[1] += e.missing / n;
      stats_[2] = std::min(stats_[2], e.min);
      stats_[3] = std::max(stats_[3], e.max);
    }
    if (!(stats_[2] <= stats_[3])) stats_[2] = stats_[3] = 0.0;  // no value sampled
    write(step);
  }

  double compute_vector(int i) override { return i >= 0 && i < 4 ? stats_[i] : 0.0; }

 private:
  enum Ave { ONE, RUNNING, WINDOW };
  enum Beyond { IGNORE, END, EXTRA };
  struct Histogram {
    std::vector<double> bins;
    double count = 0, missing = 0, min = kInf, max = -kInf;
  };

  void check_peratom_value_or_array(const SampledValue& v) {
    if (v.col == 0 && (v.kind == 'c' || v.kind == 'f') && peratom_columns(engine_, v) > 0) {
      SampledValue first = v;  // a whole per-atom array: every column
      first.col = 1;
      check_peratom_value(engine_, first, this, what_);
      return;
    }
    check_peratom_value(engine_, v, this, what_);
  }

  // Bin one value: h[0..nbins) the bins, h[nbins] the count, h[nbins+1] the
  // values not binned; lohi = {min, -max}.
  void bin(double x, std::vector<double>& h, double lohi[2]) const {
    lohi[0] = std::min(lohi[0], x);
    lohi[1] = std::min(lohi[1], -x);
    const int inner = beyond_ == EXTRA ? nbins_ - 2 : nbins_;
    int b;
    if (x < lo_ || x > hi_) {
      if (beyond_ == IGNORE) {
        h[nbins_ + 1] += 1.0;
        return;
      }
      b = x < lo_ ? 0 : nbins_ - 1;
    } else {
      // on a boundary between two bins: the lower one
      b = std::max(0, static_cast<int>(std::ceil((x - lo_) / binsize_)) - 1);
      b = std::min(b, inner - 1);
      if (beyond_ == EXTRA) b += 1;
    }
    h[b] += 1.0;
    h[nbins_] += 1.0;
  }

  void write(std::int64_t step) {
    if (file_.empty() || engine_.rank != 0) return;
    std::ostringstream os;
    os.precision(10);
    os << step << ' ' << nbins_ << ' ' << stats_[0] << ' ' << stats_[1] << ' ' << stats_[2] << ' '
       << stats_[3] << '\n';
    for (int b = 0; b < nbins_; ++b)
      os << b + 1 << ' ' << coord_[b] << ' ' << out_[b] << ' ' << (stats_[0] > 0 ? out_[b] / stats_[0] : 0.0)
         << '\n';
    write_output_block(file_, header_, os.str(), overwrite_, fp_, what_);
  }

  std::string what_;
  long long every_ = 1, nrepeat_ = 1, nfreq_ = 1;
  double lo_ = 0, hi_ = 1, binsize_ = 1;
  int nbins_ = 1;
  std::vector<SampledValue> values_;
  bool vector_mode_ = false;
  Ave ave_ = ONE;
  long long window_ = 0;
  long long start_ = 0;
  Beyond beyond_ = IGNORE;
  bool overwrite_ = false;
  std::string file_, title1_, title2_, title3_, header_;
  OutputFile fp_;  // rank 0, with a file

  SamplingSchedule schedule_;
  long long noutputs_ = 0;
  std::vector<double> coord_, sum_, out_, scratch_;
  double count_ = 0, missing_ = 0, min_ = kInf, max_ = -kInf;
  std::deque<Histogram> history_;
  double stats_[4] = {0, 0, 0, 0};
};

}  // namespace

GRANARY_FIX_STYLE("ave/histo", FixAveHisto);

}  // namespace granary
