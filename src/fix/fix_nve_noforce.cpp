// fix ID group nve/noforce: the particles of the group move with their
// velocity, x += dt v, which forces do not change (LAMMPS/LIGGGHTS: for
// particles whose velocity another fix sets). Spheres of clumps are moved by
// their body; a group that holds some is refused at the start of a run.
#include <mpi.h>

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

  void setup() override {
    const Particles& p = *engine_.particles;
    long long mine = 0, all = 0;
    for (int i = 0; i < p.nlocal; ++i)
      if ((p.mask[i] & groupbit) && p.body[i] >= 0) ++mine;
    MPI_Allreduce(&mine, &all, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
    if (all > 0) {
      throw InputError(
          "fix " + id + " (nve/noforce): " + std::to_string(all) +
          " particles of its group are spheres of clumps, which fix multisphere moves; give it a "
          "group of free spheres");
    }
  }

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
