// fix ID group setforce fx fy fz [region R]
//
// Sets the force components of every particle of the group (in the region,
// with `region`) to (fx, fy, fz) [N] after the pair forces; NULL leaves a
// component alone. A component may be an equal-style or atom-style variable
// v_name, evaluated every step. Torques are left alone. Global vector: the
// total force on those particles before it was set. Clumps are refused (a
// RunError names the sphere).
#include "core/engine.h"
#include "core/registry.h"
#include "fix/force_components.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage = "fix ID group setforce fx fy fz [region REGION]  (fx fy fz: N, v_name or NULL)";

class FixSetForce : public FixForceComponents {
 public:
  FixSetForce(Engine& engine, const Args& args)
      : FixForceComponents(engine, args, kUsage,
                           {/*allow_null*/ true, /*allow_atom*/ true, /*allow_energy*/ false}) {}

  void post_force() override {
    comp_.update();
    Particles& p = *engine_.particles;
    before_[0] = before_[1] = before_[2] = 0.0;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!comp_.selected(i, groupbit)) continue;
      if (p.body[i] >= 0) refuse_clump_sphere(i);
      for (int d = 0; d < 3; ++d) {
        before_[d] += p.f[i][d];
        if (comp_.kind(d) != ForceComponents::NONE) p.f[i][d] = comp_.value(d, i);
      }
    }
  }
};

}  // namespace

GRANARY_FIX_STYLE("setforce", FixSetForce);

}  // namespace granary
