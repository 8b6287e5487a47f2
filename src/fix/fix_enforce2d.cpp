// fix ID group enforce2d (LAMMPS/LIGGGHTS): keeps the group's particles in
// the xy plane of a 2d simulation by zeroing the z components of velocity and
// force, and the x and y components of angular velocity and torque, after the
// forces of every step (and at the start of a run). Forces other fixes add
// later in the step (fixes defined after this one) are not zeroed: define it
// last. See doc/fixes/enforce2d.md.
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixEnforce2d : public Fix {
 public:
  FixEnforce2d(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 3, 3, "fix ID group enforce2d");
    if (engine.domain->dimension != 2)
      throw InputError("fix " + id + " enforce2d needs a 2d simulation (dimension 2 before the box)");
  }
  unsigned hooks() const override { return POST_FORCE; }
  void setup() override { post_force(); }
  void post_force() override {
    Particles& p = *engine_.particles;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      p.v[i][2] = 0.0;
      p.f[i][2] = 0.0;
      p.omega[i][0] = p.omega[i][1] = 0.0;
      p.torque[i][0] = p.torque[i][1] = 0.0;
    }
  }
};

}  // namespace

GRANARY_FIX_STYLE("enforce2d", FixEnforce2d);

}  // namespace granary
