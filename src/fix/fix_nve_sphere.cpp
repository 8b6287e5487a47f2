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

  // Operations in LIGGGHTS' order (dtf / m, then (dtf / 0.4) / (r^2 m)), so
  // that both programs round alike.
  void initial_integrate() override {
    Particles& p = *engine_.particles;
    const double dt = engine_.update->dt;
    const double dtf = 0.5 * dt;
    const double dtfrot = dtf / kInertia;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit) || p.body[i] >= 0) continue;
      const double dtfm = dtf / p.rmass[i];
      p.v[i] += dtfm * p.f[i];
      p.x[i] += dt * p.v[i];
      const double dtirotate = dtfrot / (p.radius[i] * p.radius[i] * p.rmass[i]);
      p.omega[i] += dtirotate * p.torque[i];
    }
  }

  void final_integrate() override {
    Particles& p = *engine_.particles;
    const double dtf = 0.5 * engine_.update->dt;
    const double dtfrot = dtf / kInertia;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit) || p.body[i] >= 0) continue;
      const double dtfm = dtf / p.rmass[i];
      p.v[i] += dtfm * p.f[i];
      const double dtirotate = dtfrot / (p.radius[i] * p.radius[i] * p.rmass[i]);
      p.omega[i] += dtirotate * p.torque[i];
    }
  }

 private:
  static constexpr double kInertia = 0.4;  // solid sphere: I = 2/5 m r^2
};

GRANARY_FIX_STYLE("nve/sphere", FixNveSphere);

}  // namespace granary
