// fix ID group ave/atom Nevery Nrepeat Nfreq value1 value2 ...
//
// Per-particle time averages (LIGGGHTS/LAMMPS syntax and semantics): on each
// step that is a multiple of Nfreq the fix stores, for every particle of the
// group, the average of Nrepeat samples of each value taken Nevery steps apart
// and ending on that step (steps Nfreq - (Nrepeat-1)*Nevery, ..., Nfreq).
// Values: x y z vx vy vz fx fy fz (particle attributes), c_ID / c_ID[i]
// (per-atom vector or array column of a compute), f_ID / f_ID[i] (of a fix),
// v_name (atom-style variable).
// Output: one value -> per-atom vector f_ID, several -> per-atom array
// f_ID[i]. Between outputs it holds the last average; 0 before the first and
// for particles outside the group. The running sums and the averages travel
// with their particle between ranks; a particle inserted during a window
// contributes the samples taken after its insertion (the sum is still divided
// by Nrepeat).
#include <cstdint>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "fix/sampled_values.h"
#include "particles/particles.h"

namespace granary {

namespace {

const std::string kUsage =
    "fix ID group ave/atom Nevery Nrepeat Nfreq value1 value2 ... (values: x y z vx vy vz fx fy fz, c_ID, "
    "c_ID[i], f_ID, f_ID[i], v_name)";

class FixAveAtom : public Fix {
 public:
  FixAveAtom(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string what = "fix " + id + " (ave/atom)";
    if (args.size() < 7)
      throw InputError(what + " needs Nevery, Nrepeat, Nfreq and at least one value; usage: " + kUsage);
    parse_schedule(&args[3], what, every_, nrepeat_, nfreq_);
    for (std::size_t k = 6; k < args.size(); ++k)
      values_.push_back(parse_sampled_value(args[k], what, kUsage));

    ncols_ = static_cast<int>(values_.size());
    peratom_flag = true;
    peratom_cols = ncols_ == 1 ? 0 : ncols_;
    nevery = 1;  // sampling steps are tracked here (schedule_)
    // per particle: the running sums, then the last averages
    field_ = engine.particles->add_field(field_name(), 2 * ncols_, false, true);
    schedule_.set(every_, nrepeat_, nfreq_);
    schedule_.begin(engine.update->ntimestep);
  }

  unsigned hooks() const override { return END_OF_STEP; }
  bool end_of_step_due(std::int64_t step) const override { return schedule_.due(step); }

  void init() override {
    const std::string what = "fix " + id + " (ave/atom)";
    for (const SampledValue& v : values_)
      check_peratom_value(engine_, v, this, what);
    schedule_.catch_up(engine_.update->ntimestep);
  }

  // samples at the first step of a run too, when it is a sampling step
  void setup() override { end_of_step(); }

  void end_of_step() override {
    const std::int64_t step = engine_.update->ntimestep;
    if (!schedule_.due(step)) return;
    Particles& p = *engine_.particles;
    const int n = p.nlocal;
    double* data = p.extras[field_].data.data();
    const int stride = 2 * ncols_;
    if (schedule_.window_start()) {
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < ncols_; ++j)
          data[static_cast<std::size_t>(i) * stride + j] = 0.0;
    }
    for (int j = 0; j < ncols_; ++j) {
      sample_peratom(engine_, values_[j], scratch_);
      for (int i = 0; i < n; ++i)
        if (p.mask[i] & groupbit) data[static_cast<std::size_t>(i) * stride + j] += scratch_[i];
    }
    if (!schedule_.sampled(step)) return;
    // an output step: the averages of the Nrepeat samples
    const double inv = 1.0 / static_cast<double>(nrepeat_);
    for (int i = 0; i < n; ++i) {
      double* row = data + static_cast<std::size_t>(i) * stride;
      for (int j = 0; j < ncols_; ++j)
        row[ncols_ + j] = (p.mask[i] & groupbit) ? row[j] * inv : 0.0;
    }
  }

  void peratom(int col, std::vector<double>& out) override {
    if ((ncols_ == 1 && col != 0) || (ncols_ > 1 && (col < 1 || col > ncols_))) {
      throw InputError("fix " + id + " (ave/atom) averages " + std::to_string(ncols_) + " value(s): use " +
                       (ncols_ == 1 ? "f_" + id : "f_" + id + "[1.." + std::to_string(ncols_) + "]"));
    }
    const Particles& p = *engine_.particles;
    const std::vector<double>& data = p.extras[field_].data;
    const int j = ncols_ + (col == 0 ? 0 : col - 1);
    out.assign(p.nlocal, 0.0);
    for (int i = 0; i < p.nlocal; ++i)
      out[i] = data[static_cast<std::size_t>(i) * 2 * ncols_ + j];
  }

  void unfixed() override { engine_.particles->release_field(field_name()); }

 private:
  std::string field_name() const { return "ave/atom/" + id; }

  long long every_ = 1, nrepeat_ = 1, nfreq_ = 1;
  std::vector<SampledValue> values_;
  int ncols_ = 0;
  int field_ = -1;
  SamplingSchedule schedule_;
  std::vector<double> scratch_;
};

}  // namespace

GRANARY_FIX_STYLE("ave/atom", FixAveAtom);

}  // namespace granary
