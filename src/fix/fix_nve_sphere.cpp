// fix nve/sphere: velocity-Verlet integration of position, velocity and spin
// of free spheres (sub-spheres of clumps are integrated by their body).
#include <cmath>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

class FixNveSphere : public Fix {
 public:
  FixNveSphere(Engine& engine, const Args& args) : Fix(engine, args) {
    if (args.size() > 3) throw InputError("fix nve/sphere takes no arguments here; usage: fix ID group nve/sphere");
    time_integrate = true;
  }
  unsigned hooks() const override { return INITIAL_INTEGRATE | FINAL_INTEGRATE; }

  void initial_integrate() override {
    Particles& p = *engine_.particles;
    const double dt = engine_.update->dt;
    const double dtf = 0.5 * dt;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit) || p.body[i] >= 0) continue;
      const double inv_m = 1.0 / p.rmass[i];
      p.v[i] += dtf * inv_m * p.f[i];
      p.x[i] += dt * p.v[i];
      const double inv_i = 1.0 / (kInertia * p.rmass[i] * p.radius[i] * p.radius[i]);
      p.omega[i] += dtf * inv_i * p.torque[i];
    }
  }

  void final_integrate() override {
    Particles& p = *engine_.particles;
    const double dtf = 0.5 * engine_.update->dt;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit) || p.body[i] >= 0) continue;
      p.v[i] += dtf / p.rmass[i] * p.f[i];
      const double inv_i = 1.0 / (kInertia * p.rmass[i] * p.radius[i] * p.radius[i]);
      p.omega[i] += dtf * inv_i * p.torque[i];
    }
  }

 private:
  static constexpr double kInertia = 0.4;  // solid sphere: I = 2/5 m r^2
};

GRANARY_FIX_STYLE("nve/sphere", FixNveSphere);

}  // namespace granary
