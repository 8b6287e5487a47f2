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
    if (args.size() > 3)
      throw InputError("fix nve/sphere takes no arguments here; usage: fix ID group nve/sphere");
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
    Vec3 *const x = p.x.data(), *const v = p.v.data(), *const omega = p.omega.data();
    const Vec3 *const f = p.f.data(), *const torque = p.torque.data();
    const double *const rmass = p.rmass.data(), *const radius = p.radius.data();
    const int* const mask = p.mask.data();
    const tagint* const body = p.body.data();
    const int bit = groupbit, n = p.nlocal;
    for (int i = 0; i < n; ++i) {
      if (!(mask[i] & bit) || body[i] >= 0) continue;
      const double dtfm = dtf / rmass[i];
      v[i] += dtfm * f[i];
      x[i] += dt * v[i];
      const double dtirotate = dtfrot / (radius[i] * radius[i] * rmass[i]);
      omega[i] += dtirotate * torque[i];
    }
  }

  void final_integrate() override {
    Particles& p = *engine_.particles;
    const double dtf = 0.5 * engine_.update->dt;
    const double dtfrot = dtf / kInertia;
    Vec3 *const v = p.v.data(), *const omega = p.omega.data();
    const Vec3 *const f = p.f.data(), *const torque = p.torque.data();
    const double *const rmass = p.rmass.data(), *const radius = p.radius.data();
    const int* const mask = p.mask.data();
    const tagint* const body = p.body.data();
    const int bit = groupbit, n = p.nlocal;
    for (int i = 0; i < n; ++i) {
      if (!(mask[i] & bit) || body[i] >= 0) continue;
      const double dtfm = dtf / rmass[i];
      v[i] += dtfm * f[i];
      const double dtirotate = dtfrot / (radius[i] * radius[i] * rmass[i]);
      omega[i] += dtirotate * torque[i];
    }
  }

 private:
  static constexpr double kInertia = 0.4;  // solid sphere: I = 2/5 m r^2
};

GRANARY_FIX_STYLE("nve/sphere", FixNveSphere);

}  // namespace granary
