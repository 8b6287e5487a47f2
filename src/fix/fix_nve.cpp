// fix ID group nve: velocity-Verlet integration of position and velocity of
// the particles of the group (LAMMPS/LIGGGHTS `fix nve`): v += dt/2 f/m,
// x += dt v, v += dt/2 f/m. The spin is left alone, so torques turn nothing
// (point particles; `fix nve/sphere` integrates the spin too). Spheres of
// clumps are moved by their body; a group that holds some is refused at the
// start of a run. nve/sph: the same for SPH particles (atom_style sph).
#include <memory>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

// nve/sph: the same integration for the particles of atom_style sph (their
// densities are advanced by fix sph/density/continuity)
class FixNve : public Fix {
 public:
  FixNve(Engine& engine, const Args& args, bool sph) : Fix(engine, args), sph_(sph) {
    require_args(args, 3, 3, sph ? "fix ID group nve/sph" : "fix ID group nve");
    time_integrate = true;
  }

  unsigned hooks() const override { return INITIAL_INTEGRATE | FINAL_INTEGRATE; }

  void init() override {
    if (sph_ && !engine_.particles->sph) throw InputError("fix " + id + " nve/sph needs atom_style sph");
  }
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

 private:
  bool sph_;
};

}  // namespace

static const bool nve_styles_registered = [] {
  for (const bool sph : {false, true})
    FixRegistry::instance().add(sph ? "nve/sph" : "nve",
                                [sph](Engine& e, const Args& a) -> std::unique_ptr<Fix> {
                                  return std::make_unique<FixNve>(e, a, sph);
                                });
  return true;
}();

}  // namespace granary
