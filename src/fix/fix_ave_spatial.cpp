// fix ID group ave/spatial Nevery Nrepeat Nfreq dim origin delta [dim origin delta ...] value1 ... keyword
// args
//
// Spatial bins (1d layers, 2d pencils or 3d boxes) of per-particle values,
// averaged over time (LIGGGHTS/LAMMPS syntax and output format). Each output
// step (a multiple of Nfreq) the fix averages the Nrepeat samples taken Nevery
// steps apart and ending on that step, then combines the result with earlier
// outputs (ave one / running / window M).
// Bins: in each binned dimension the edges are origin + k * delta, as many as
// cover the box; they are laid out afresh at the first sample of every
// window (a shrink-wrapped box changes them). Along a periodic dimension a
// particle is binned at its position wrapped into the box; a particle beyond
// the first or last bin of a dimension counts in that bin. Bins are numbered with the last
// dimension varying fastest.
// Values: vx vy vz fx fy fz (and x y z), c_ID / c_ID[i], f_ID / f_ID[i],
// v_name (atom-style variable): the mean over the particles of a bin;
// density/number, density/mass: particles or mass per bin volume.
// norm all: sum over all samples / count over all samples; norm sample: the
// mean of the samples' per-sample means. The count column is the mean count
// per sample.
// Output: a file (header of three lines, then per output "step nbins" and one
// line "bin coord... count value..." per bin).
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "fix/sampled_values.h"
#include "particles/particles.h"

namespace granary {

namespace {

const std::string kUsage =
    "fix ID group ave/spatial Nevery Nrepeat Nfreq dim origin delta [dim origin delta ...] value1 ... "
    "[norm all|sample] [units box|lattice|reduced] [region ID] [ave one|running|window M] [file F] "
    "[overwrite] [title1|title2|title3 TEXT] [write_ts yes|no] (dim: x y z; origin: lower center upper or a "
    "coordinate; values: vx vy vz fx fy fz density/number density/mass c_ID c_ID[i] f_ID f_ID[i] v_name)";

class FixAveSpatial : public Fix {
 public:
  FixAveSpatial(Engine& engine, const Args& args) : Fix(engine, args) {
    what_ = "fix " + id + " (ave/spatial)";
    if (args.size() < 10)
      throw InputError(
          what_ + " needs Nevery, Nrepeat, Nfreq, a dim/origin/delta triple and a value; usage: " + kUsage);
    parse_schedule(&args[3], what_, every_, nrepeat_, nfreq_);
    std::size_t k = 6;
    while (k < args.size() && ndim_ < 3 && (args[k] == "x" || args[k] == "y" || args[k] == "z")) {
      if (k + 2 >= args.size())
        throw InputError(what_ + ": dim " + args[k] +
                         " needs an origin and a bin thickness; usage: " + kUsage);
      Dim d;
      d.axis = args[k][0] - 'x';
      for (int j = 0; j < ndim_; ++j)
        if (dims_[j].axis == d.axis) throw InputError(what_ + ": dimension " + args[k] + " is binned twice");
      const std::string& o = args[k + 1];
      if (o == "lower" || o == "center" || o == "upper") {
        d.origin_word = o;
      } else {
        d.origin = parse_double(o, what_ + " origin");
      }
      d.delta = parse_double(args[k + 2], what_ + " delta");
      if (!(d.delta > 0.0))
        throw InputError(what_ + ": the bin thickness must be positive (got " + args[k + 2] + ")");
      dims_[ndim_++] = d;
      k += 3;
    }
    if (ndim_ == 0)
      throw InputError(what_ + ": the bins need a dimension x, y or z after Nfreq; usage: " + kUsage);
    static const std::vector<std::string> kKeywords = {"norm",      "units",    "region", "ave",
                                                       "file",      "title1",   "title2", "title3",
                                                       "overwrite", "write_ts", "std"};
    for (; k < args.size(); ++k) {
      if (std::find(kKeywords.begin(), kKeywords.end(), args[k]) != kKeywords.end()) break;
      Value v;
      if (args[k] == "density/number" || args[k] == "density/mass") {
        v.density = args[k] == "density/number" ? 1 : 2;
        v.sampled.text = args[k];
      } else {
        v.sampled = parse_sampled_value(args[k], what_, kUsage);
      }
      values_.push_back(v);
    }
    if (values_.empty()) throw InputError(what_ + " needs at least one value; usage: " + kUsage);
    bool overwrite = false;
    std::string units = "box";
    for (; k < args.size(); ++k) {
      const std::string& key = args[k];
      if (key == "overwrite") {
        overwrite = true;
        continue;
      }
      if (key == "std")
        throw InputError(what_ +
                         ": the std keyword (LIGGGHTS' sample statistics) is not supported; leave it out");
      if (k + 1 >= args.size())
        throw InputError(what_ + ": keyword '" + key + "' needs a value; usage: " + kUsage);
      const std::string& val = args[++k];
      if (key == "norm") {
        if (val != "all" && val != "sample")
          throw InputError(what_ + ": norm must be all or sample (got '" + val + "')");
        norm_sample_ = val == "sample";
      } else if (key == "units") {
        if (val != "box" && val != "lattice" && val != "reduced")
          throw InputError(what_ + ": units must be box, lattice or reduced (got '" + val + "')");
        units = val;
      } else if (key == "region") {
        region_id_ = val;
        engine.domain->region_or_error(val, what_);
      } else if (key == "ave") {
        ave_ = static_cast<Ave>(parse_ave_keyword(args, k, what_, window_));
      } else if (key == "file") {
        file_ = val;
      } else if (key == "title1") {
        title_[0] = val;
        title_set_[0] = true;
      } else if (key == "title2") {
        title_[1] = val;
        title_set_[1] = true;
      } else if (key == "title3") {
        title_[2] = val;
        title_set_[2] = true;
      } else if (key == "write_ts") {
        if (val != "yes" && val != "no") throw InputError(what_ + ": write_ts must be yes or no");
        write_ts_ = val == "yes";
      } else {
        throw InputError(what_ + ": unknown keyword '" + key + "'; usage: " + kUsage);
      }
    }
    if (overwrite && ave_ != RUNNING)
      throw InputError(what_ + ": overwrite needs ave running (as in LIGGGHTS)");
    overwrite_ = overwrite;
    reduced_ = units == "reduced";
    if (units == "lattice") {
      const Domain& dom = *engine.domain;
      if (dom.lattice_style == "none")
        throw InputError(what_ +
                         " uses units lattice but no lattice is defined; add a lattice command or use "
                         "units box");
      for (int j = 0; j < ndim_; ++j) {
        dims_[j].delta *= dom.lattice_spacing[dims_[j].axis];
        dims_[j].origin *= dom.lattice_spacing[dims_[j].axis];
      }
    }
    nevery = 1;  // sampling steps are tracked here (schedule_)

    if (!file_.empty()) {
      if (!title_set_[0]) title_[0] = "# Spatial-averaged data for fix " + id + " and group " + args[1];
      if (!title_set_[1]) title_[1] = "# Timestep Number-of-bins";
      if (!title_set_[2]) {
        title_[2] = "# Bin";
        if (ndim_ == 1) {
          title_[2] += " Coord";
        } else {
          for (int j = 0; j < ndim_; ++j)
            title_[2] += " Coord" + std::to_string(j + 1);
        }
        title_[2] += " Ncount";
        for (const Value& v : values_)
          title_[2] += " " + v.sampled.text;
      }
      for (const std::string& t : title_)
        if (!t.empty()) header_ += t + "\n";  // an empty title leaves its line out
      fp_ = start_output_file(engine, file_, header_, !overwrite_, what_);
    }
    schedule_.set(every_, nrepeat_, nfreq_);
    schedule_.begin(engine.update->ntimestep);
  }

  unsigned hooks() const override { return END_OF_STEP; }
  bool end_of_step_due(std::int64_t step) const override { return schedule_.due(step); }

  void init() override {
    for (const Value& v : values_)
      if (!v.density) check_peratom_value(engine_, v.sampled, this, what_);
    if (!region_id_.empty()) engine_.domain->region_or_error(region_id_, what_);
    schedule_.catch_up(engine_.update->ntimestep);
  }

  void setup() override { end_of_step(); }

  void end_of_step() override {
    const std::int64_t step = engine_.update->ntimestep;
    if (!schedule_.due(step)) return;
    const int nv = static_cast<int>(values_.size());
    if (schedule_.window_start()) {
      layout_bins();
      sum_.assign(static_cast<std::size_t>(nbins_) * (nv + 1), 0.0);
    }
    // this sample: per bin the count, then the sum of every value
    const Particles& p = *engine_.particles;
    const Region* region = region_id_.empty() ? nullptr : engine_.domain->region_or_error(region_id_, what_);
    std::vector<int> bin(p.nlocal, -1);
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      if (region && !region->match(p.x[i])) continue;
      bin[i] = bin_of(p.x[i]);
    }
    const int stride = nv + 1;
    std::vector<double> one(static_cast<std::size_t>(nbins_) * stride, 0.0);
    for (int i = 0; i < p.nlocal; ++i)
      if (bin[i] >= 0) one[static_cast<std::size_t>(bin[i]) * stride] += 1.0;
    for (int j = 0; j < nv; ++j) {
      const Value& v = values_[j];
      if (v.density == 1) {
        for (int i = 0; i < p.nlocal; ++i)
          if (bin[i] >= 0) one[static_cast<std::size_t>(bin[i]) * stride + 1 + j] += 1.0;
        continue;
      }
      if (v.density == 2) {
        for (int i = 0; i < p.nlocal; ++i)
          if (bin[i] >= 0) one[static_cast<std::size_t>(bin[i]) * stride + 1 + j] += p.rmass[i];
        continue;
      }
      sample_peratom(engine_, v.sampled, scratch_);
      for (int i = 0; i < p.nlocal; ++i)
        if (bin[i] >= 0) one[static_cast<std::size_t>(bin[i]) * stride + 1 + j] += scratch_[i];
    }
    std::vector<double> all(one.size());
    MPI_Allreduce(one.data(), all.data(), static_cast<int>(one.size()), MPI_DOUBLE, MPI_SUM, engine_.world);
    // densities per bin volume; with norm sample, every value as this sample's mean
    for (int b = 0; b < nbins_; ++b) {
      double* row = &all[static_cast<std::size_t>(b) * stride];
      for (int j = 0; j < nv; ++j) {
        if (values_[j].density) {
          row[1 + j] /= binvol_;
        } else if (norm_sample_) {
          row[1 + j] = row[0] > 0.0 ? row[1 + j] / row[0] : 0.0;
        }
      }
    }
    for (std::size_t m = 0; m < all.size(); ++m)
      sum_[m] += all[m];

    if (!schedule_.sampled(step)) return;
    // an output step: the average over the window's samples
    std::vector<double> now(sum_.size());
    const double inv = 1.0 / static_cast<double>(nrepeat_);
    for (int b = 0; b < nbins_; ++b) {
      const double* s = &sum_[static_cast<std::size_t>(b) * stride];
      double* o = &now[static_cast<std::size_t>(b) * stride];
      o[0] = s[0] * inv;
      for (int j = 0; j < nv; ++j) {
        if (values_[j].density || norm_sample_)
          o[1 + j] = s[1 + j] * inv;
        else
          o[1 + j] = s[0] > 0.0 ? s[1 + j] / s[0] : 0.0;
      }
    }
    // combined with earlier outputs; a changed number of bins starts afresh
    if (ave_ == ONE || (!history_.empty() && history_.back().size() != now.size())) {
      history_.clear();
      noutputs_ = 0;
    }
    if (ave_ == RUNNING) {
      if (history_.empty()) history_.emplace_back(now.size(), 0.0);
      for (std::size_t m = 0; m < now.size(); ++m)
        history_.front()[m] += now[m];
      ++noutputs_;
    } else {
      history_.push_back(now);
      if (ave_ == WINDOW && static_cast<long long>(history_.size()) > window_) history_.pop_front();
    }
    const double n = ave_ == RUNNING ? static_cast<double>(noutputs_) : static_cast<double>(history_.size());
    out_.assign(now.size(), 0.0);
    for (const auto& h : history_)
      for (std::size_t m = 0; m < now.size(); ++m)
        out_[m] += h[m] / n;
    write(step);
  }

 private:
  enum Ave { ONE, RUNNING, WINDOW };
  struct Dim {
    int axis = 0;
    std::string origin_word;  // lower, center, upper, or empty: `origin`
    double origin = 0.0;
    double delta = 1.0;
    // laid out at the start of each window (reduced units: in [0, 1] fractions)
    double lo = 0.0;
    int n = 1;
  };
  struct Value {
    int density = 0;  // 1: density/number, 2: density/mass
    SampledValue sampled;
  };

  // The bins of each dimension: edges origin + k delta from below the box's
  // lower bound to above its upper bound.
  void layout_bins() {
    const Domain& dom = *engine_.domain;
    nbins_ = 1;
    binvol_ = 1.0;
    for (int j = 0; j < ndim_; ++j) {
      Dim& d = dims_[j];
      const int a = d.axis;
      const double lo = reduced_ ? 0.0 : dom.boxlo[a], hi = reduced_ ? 1.0 : dom.boxhi[a];
      double origin = d.origin;
      if (d.origin_word == "lower") origin = lo;
      if (d.origin_word == "upper") origin = hi;
      if (d.origin_word == "center") origin = 0.5 * (lo + hi);
      const double klo = std::floor((lo - origin) / d.delta), khi = std::ceil((hi - origin) / d.delta);
      d.lo = origin + klo * d.delta;
      d.n = std::max(1, static_cast<int>(std::lround(khi - klo)));
      nbins_ *= d.n;
    }
    for (int a = 0; a < 3; ++a) {
      double extent = dom.prd[a];
      for (int j = 0; j < ndim_; ++j)
        if (dims_[j].axis == a) extent = reduced_ ? dims_[j].delta * dom.prd[a] : dims_[j].delta;
      binvol_ *= extent;
    }
  }

  int bin_of(const Vec3& x) const {
    const Domain& dom = *engine_.domain;
    int b = 0;
    for (int j = 0; j < ndim_; ++j) {
      const Dim& d = dims_[j];
      const int a = d.axis;
      double c = reduced_ ? (x[a] - dom.boxlo[a]) * (1.0 / dom.prd[a]) : x[a];
      if (dom.periodic[a]) {  // a particle not yet wrapped back into the box
        const double lo = reduced_ ? 0.0 : dom.boxlo[a], len = reduced_ ? 1.0 : dom.prd[a];
        if (c < lo) c += len;
        if (c >= lo + len) c -= len;
      }
      int k = static_cast<int>(std::floor((c - d.lo) * (1.0 / d.delta)));
      k = std::clamp(k, 0, d.n - 1);
      b = b * d.n + k;
    }
    return b;
  }

  void write(std::int64_t step) {
    if (file_.empty() || engine_.rank != 0) return;
    const int stride = static_cast<int>(values_.size()) + 1;
    std::ostringstream os;
    os.precision(6);
    if (write_ts_) os << step << ' ' << nbins_ << '\n';
    for (int b = 0; b < nbins_; ++b) {
      os << "  " << b + 1;
      // the bin's centre in each dimension (bins numbered with the last dimension fastest)
      int rest = b;
      std::vector<double> centre(ndim_);
      for (int j = ndim_ - 1; j >= 0; --j) {
        const int k = rest % dims_[j].n;
        rest /= dims_[j].n;
        centre[j] = dims_[j].lo + (k + 0.5) * dims_[j].delta;
      }
      for (double c : centre)
        os << ' ' << c;
      for (int m = 0; m < stride; ++m)
        os << ' ' << out_[static_cast<std::size_t>(b) * stride + m];
      os << '\n';
    }
    write_output_block(file_, header_, os.str(), overwrite_, fp_, what_);
  }

  std::string what_;
  long long every_ = 1, nrepeat_ = 1, nfreq_ = 1;
  Dim dims_[3];
  int ndim_ = 0;
  std::vector<Value> values_;
  bool norm_sample_ = false, reduced_ = false, write_ts_ = true, overwrite_ = false;
  std::string region_id_;
  Ave ave_ = ONE;
  long long window_ = 0;
  std::string file_, title_[3], header_;
  bool title_set_[3] = {false, false, false};
  OutputFile fp_;  // rank 0, with a file

  SamplingSchedule schedule_;
  int nbins_ = 1;
  double binvol_ = 1.0;
  long long noutputs_ = 0;
  std::vector<double> sum_, out_, scratch_;
  std::deque<std::vector<double>> history_;
};

}  // namespace

GRANARY_FIX_STYLE("ave/spatial", FixAveSpatial);

}  // namespace granary
