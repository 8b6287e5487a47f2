// fix ID group nve: velocity-Verlet integration of position and velocity of
// the particles of the group (LAMMPS/LIGGGHTS `fix nve`): v += dt/2 f/m,
// x += dt v, v += dt/2 f/m. The spin is left alone, so torques turn nothing
// (point particles; `fix nve/sphere` integrates the spin too). Spheres of
// clumps are moved by their body; a group that holds some is refused at the
// start of a run.
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixNve : public Fix {
 public:
  FixNve(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 3, 3, "fix ID group nve");
    time_integrate = true;
  }

  unsigned hooks() const override { return INITIAL_INTEGRATE | FINAL_INTEGRATE; }

  void setup() override { require_free_spheres(); }

  // (dt/2) / m as LIGGGHTS computes it, so that both programs round alike
  void initial_integrate() override {
    Particles& p = *engine_.particles;
    const double dt = engine_.update->dt, dtf = 0.5 * dt;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      p.v[i] += (dtf / p.rmass[i]) * p.f[i];
      p.x[i] += dt * p.v[i];
    }
  }

  void final_integrate() override {
    Particles& p = *engine_.particles;
    const double dtf = 0.5 * engine_.update->dt;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & groupbit) p.v[i] += (dtf / p.rmass[i]) * p.f[i];
  }
};

}  // namespace

GRANARY_FIX_STYLE("nve", FixNve);

}  // namespace granary
