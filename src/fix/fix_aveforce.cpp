// fix ID group aveforce fx fy fz [region R]
//
// Gives every particle of the group (in the region, with `region`) the same
// force after the pair forces: per component, the average force over those
// particles (over all ranks) plus fx, fy or fz [N]; NULL leaves a component
// alone. Components may be equal-style variables. The group then moves as one
// when its particles start with one velocity and have equal masses. Global
// vector: the total force on those particles before the fix. Clumps are
// refused (a RunError names the sphere).
#include <mpi.h>

#include "core/engine.h"
#include "core/registry.h"
#include "fix/force_components.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group aveforce fx fy fz [region REGION]  (fx fy fz: N, equal-style v_name or NULL)";

class FixAveForce : public FixForceComponents {
 public:
  FixAveForce(Engine& engine, const Args& args)
      : FixForceComponents(engine, args, kUsage,
                           {/*allow_null*/ true, /*allow_atom*/ false, /*allow_energy*/ false}) {}

  void post_force() override {
    comp_.update();
    Particles& p = *engine_.particles;
    double local[4] = {0, 0, 0, 0}, all[4];
    for (int i = 0; i < p.nlocal; ++i) {
      if (!comp_.selected(i, groupbit)) continue;
      if (p.body[i] >= 0) refuse_clump_sphere(i);
      for (int d = 0; d < 3; ++d)
        local[d] += p.f[i][d];
      local[3] += 1.0;
    }
    for (int d = 0; d < 3; ++d)
      before_[d] = local[d];
    MPI_Allreduce(local, all, 4, MPI_DOUBLE, MPI_SUM, engine_.world);
    if (all[3] == 0.0) return;
    double set[3];
    for (int d = 0; d < 3; ++d)
      set[d] = all[d] / all[3] + comp_.value(d, 0);
    for (int i = 0; i < p.nlocal; ++i) {
      if (!comp_.selected(i, groupbit)) continue;
      for (int d = 0; d < 3; ++d)
        if (comp_.kind(d) != ForceComponents::NONE) p.f[i][d] = set[d];
    }
  }
};

}  // namespace

GRANARY_FIX_STYLE("aveforce", FixAveForce);

}  // namespace granary
