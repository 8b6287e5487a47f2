// fix ID group store/state N input1 input2 ... [com yes|no] (LAMMPS,
// LIGGGHTS): per-particle values stored for later use: particle attributes
// (every name of dump custom: id type mass radius x y z xs xu ix vx fx omegax
// tqx ...), c_ID, c_ID[i], f_ID, f_ID[i], v_name (atom-style variable).
// Attributes are stored when the fix is defined; computes, fixes and
// variables at the start of the first run after it (they may need a run's
// set-up). With N > 0 every value is stored again on every multiple of N
// steps; with N = 0 never. With com yes, xu yu zu are stored relative to the
// group's centre of mass. Output: a per-atom vector (one input) or array
// (f_ID[i]); 0 for particles outside the group and for particles created
// after the last store. The values are a per-particle field written to
// restart files: defined again with the same ID after read_restart, the fix
// keeps them. See doc/fixes/store_state.md.
#include <string>
#include <vector>

#include "core/atom_properties.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/groups.h"
#include "fix/fix.h"
#include "fix/sampled_values.h"
#include "particles/particles.h"

namespace granary {

namespace {

const std::string kUsage =
    "fix ID group store/state N input1 input2 ... [com yes|no] (inputs: particle attributes as in dump "
    "custom, "
    "c_ID, c_ID[i], f_ID, f_ID[i], v_name)";

class FixStoreState : public Fix {
 public:
  FixStoreState(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string what = "fix " + id + " (store/state)";
    if (args.size() < 5) throw InputError(what + " needs N and at least one input; usage: " + kUsage);
    every_ = parse_int(args[3], what + " N");
    if (every_ < 0) throw InputError(what + ": N must be 0 (store once) or positive");
    if (every_ > 0) nevery = static_cast<int>(every_);
    std::size_t end = args.size();
    if (end >= 2 && args[end - 2] == "com") {
      com_ = parse_bool(args[end - 1], what + " com");
      end -= 2;
    }
    for (std::size_t k = 4; k < end; ++k) {
      const std::string& w = args[k];
      if (find_atom_property(w)) {
        values_.push_back(SampledValue{'a', w, 0, w});
      } else if (w.size() > 2 && w[1] == '_') {
        values_.push_back(parse_sampled_value(w, what, kUsage));
      } else {
        const std::string hint = did_you_mean(w, atom_property_names());
        throw InputError(what + ": unknown input '" + w + "'" + (hint.empty() ? "" : "; " + hint) +
                         "; usage: " + kUsage);
      }
    }
    if (values_.empty()) throw InputError(what + " needs at least one input; usage: " + kUsage);
    ncols_ = static_cast<int>(values_.size());
    peratom_flag = true;
    peratom_cols = ncols_ == 1 ? 0 : ncols_;
    Particles& p = *engine.particles;
    const bool restored = p.find_field(field_name()) >= 0;  // from a restart file
    field_ = p.add_field(field_name(), ncols_, false, true);
    stored_refs_ = restored;
    if (!restored) store(true);
  }

  unsigned hooks() const override { return every_ > 0 ? END_OF_STEP : 0u; }

  void init() override {
    const std::string what = "fix " + id + " (store/state)";
    for (const SampledValue& v : values_)
      if (v.kind != 'a') check_peratom_value(engine_, v, this, what);
  }

  // computes, fixes and variables are stored at the start of the first run
  void setup() override {
    if (!stored_refs_) store(false);
    stored_refs_ = true;
  }

  void end_of_step() override {
    if (engine_.update->ntimestep % every_ == 0) store(false);
  }

  void peratom(int col, std::vector<double>& out) override {
    if ((ncols_ == 1 && col != 0) || (ncols_ > 1 && (col < 1 || col > ncols_))) {
      throw InputError("fix " + id + " (store/state) stores " + std::to_string(ncols_) + " value(s): use " +
                       (ncols_ == 1 ? "f_" + id : "f_" + id + "[1.." + std::to_string(ncols_) + "]"));
    }
    const Particles& p = *engine_.particles;
    const std::vector<double>& data = p.extras[field_].data;
    const int j = col == 0 ? 0 : col - 1;
    out.assign(p.nlocal, 0.0);
    for (int i = 0; i < p.nlocal; ++i)
      out[i] = data[static_cast<std::size_t>(i) * ncols_ + j];
  }

  void unfixed() override { engine_.particles->release_field(field_name()); }

 private:
  std::string field_name() const { return "store/state/" + id; }

  // Store every input (attributes_only: the particle attributes, at definition).
  void store(bool attributes_only) {
    Particles& p = *engine_.particles;
    const int n = p.nlocal;
    Vec3 xcm(0, 0, 0);
    if (com_) xcm = engine_.groups->xcm(igroup);  // collective: every rank calls it
    for (int j = 0; j < ncols_; ++j) {
      const SampledValue& v = values_[j];
      if (attributes_only && v.kind != 'a') continue;
      sample_peratom(engine_, v, scratch_);
      if (com_ && v.kind == 'a' && (v.id == "xu" || v.id == "yu" || v.id == "zu")) {
        const double c = xcm[v.id[0] - 'x'];
        for (double& x : scratch_)
          x -= c;
      }
      double* data = p.extras[field_].data.data();
      for (int i = 0; i < n; ++i)
        data[static_cast<std::size_t>(i) * ncols_ + j] = (p.mask[i] & groupbit) ? scratch_[i] : 0.0;
    }
  }

  long long every_ = 0;
  bool com_ = false;
  bool stored_refs_ = false;
  std::vector<SampledValue> values_;
  int ncols_ = 0;
  int field_ = -1;
  std::vector<double> scratch_;
};

}  // namespace

GRANARY_FIX_STYLE("store/state", FixStoreState);

}  // namespace granary
