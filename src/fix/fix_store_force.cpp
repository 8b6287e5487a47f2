// fix ID group store/force: keeps a copy of the force on each particle of the
// group as it is when the fix's turn comes after the pair forces (post_force,
// in the order the fixes were defined). Per-atom array of 3 columns f_ID[1..3]
// [N]; 0 for particles outside the group. The copy travels with its particle
// between ranks.
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixStoreForce : public Fix {
 public:
  FixStoreForce(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 3, 3, "fix ID group store/force");
    field_ = engine.particles->add_field(field_name(), 3, false, true);
    peratom_flag = true;
    peratom_cols = 3;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void post_force() override {
    Particles& p = *engine_.particles;
    double* const stored = p.extras[field_].data.data();
    for (int i = 0; i < p.nlocal; ++i)
      for (int d = 0; d < 3; ++d)
        stored[3 * i + d] = (p.mask[i] & groupbit) ? p.f[i][d] : 0.0;
  }

  void peratom(int col, std::vector<double>& out) override {
    if (col < 1 || col > 3)
      throw InputError("fix " + id + " (store/force) is a per-atom array: give a column f_" + id + "[1..3]");
    const Particles& p = *engine_.particles;
    const std::vector<double>& stored = p.extras[field_].data;
    out.assign(p.nlocal, 0.0);
    for (int i = 0; i < p.nlocal; ++i)
      out[i] = stored[3 * i + col - 1];
  }

  void unfixed() override { engine_.particles->release_field(field_name()); }

 private:
  std::string field_name() const { return "store/force/" + id; }
  int field_ = -1;
};

}  // namespace

GRANARY_FIX_STYLE("store/force", FixStoreForce);

}  // namespace granary
