// fix ID group nve/noforce: the particles of the group move with their
// velocity, x += dt v, which forces do not change (LAMMPS/LIGGGHTS: for
// particles whose velocity another fix sets). Spheres of clumps are moved by
// their body; a group that holds some is refused at the start of a run.
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixNveNoforce : public Fix {
 public:
  FixNveNoforce(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 3, 3, "fix ID group nve/noforce");
    time_integrate = true;
  }

  unsigned hooks() const override { return INITIAL_INTEGRATE; }

  void setup() override { require_free_spheres(); }

  void initial_integrate() override {
    Particles& p = *engine_.particles;
    const double dt = engine_.update->dt;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & groupbit) p.x[i] += dt * p.v[i];
  }
};

}  // namespace

GRANARY_FIX_STYLE("nve/noforce", FixNveNoforce);

}  // namespace granary
