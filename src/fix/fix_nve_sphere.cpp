// fix nve/sphere: velocity-Verlet integration of position, velocity and spin
// of free spheres (sub-spheres of clumps are integrated by their body).
#include <mpi.h>

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/modify.h"
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

  // The second half kick may wait for the next step's first one (the same
  // forces: none are computed in between) when nothing reads the velocities
  // in between (Update::step_observed) and no other fix acts in the
  // integration hooks on particles (another integrator of the same spheres
  // would see, or add to, velocities missing a kick); both kicks and the
  // drift are then one pass over the particles, with the same operations in
  // the same order.
  void init() override {
    if (pending_) {  // (a run left at an unobserved step: not in a normal run)
      pending_ = false;
      integrate<Pass::kSecond>(pending_dt_);
    }
    defer_ok_ = true;
    for (const auto& f : engine_.modify->fixes) {
      if (f.get() == this) continue;
      if ((f->hooks() & (INITIAL_INTEGRATE | FINAL_INTEGRATE)) && !kicks_commute_with(f->style))
        defer_ok_ = false;
    }
  }

  // Says once when the group holds spheres of clumps: they are left to fix
  // multisphere here, while LIGGGHTS 3.8 integrates them a second time.
  void setup() override {
    if (noted_) return;
    const long long all = clump_spheres_in_group();
    if (all == 0) return;
    noted_ = true;
    engine_.logger->print(
        "INFO: fix " + id + " (nve/sphere): " + std::to_string(all) +
        " particles of its group are spheres of clumps; fix multisphere integrates them and "
        "nve/sphere leaves them alone (LIGGGHTS 3.8 integrates them a second time; see "
        "doc/liggghts_compatibility.md)\n");
  }

  // Operations in LIGGGHTS' order (dtf / m, then (dtf / 0.4) / (r^2 m)), so
  // that both programs round alike.
  void initial_integrate() override {
    const double dt = engine_.update->dt;
    if (pending_) {
      pending_ = false;
      if (pending_dt_ == dt) {
        integrate<Pass::kBoth>(dt);
        return;
      }
      integrate<Pass::kSecond>(pending_dt_);
    }
    integrate<Pass::kFirst>(dt);
  }

  void final_integrate() override {
    if (defer_ok_ && !engine_.update->step_observed()) {
      pending_ = true;
      pending_dt_ = engine_.update->dt;
      return;
    }
    integrate<Pass::kSecond>(engine_.update->dt);
  }

 private:
  static constexpr double kInertia = 0.4;  // solid sphere: I = 2/5 m r^2
  bool noted_ = false;
  bool defer_ok_ = false;    // init(): the second half kick may be deferred
  bool pending_ = false;     // the last step's second half kick is still to be made
  double pending_dt_ = 0.0;  // its timestep

  // Fixes whose integration hooks leave the free spheres' velocities alone:
  // the clumps' integrator, the mesh fixes and the heat conduction.
  static bool kicks_commute_with(const std::string& style) {
    return style == "multisphere" || style == "multisphere/break" || style == "move/mesh" ||
           style == "mesh/surface/stress" || style == "mesh/surface/stress/servo" || style == "heat/gran" ||
           style == "heat/gran/conduction";
  }

  // kFirst: kick and drift (start of a step); kSecond: kick (end of a step);
  // kBoth: the deferred kick of the last step (of the same timestep), then
  // this step's kick and drift.
  enum class Pass { kFirst, kSecond, kBoth };

  // Half-step kick of v and omega (and, in the first half, the drift of x).
  // The two divisions per particle are made for two particles at once in the
  // lanes of packed operations (the same IEEE result per lane); the lanes of
  // particles outside the group or in clumps are computed and not used.
  template <Pass kPass>
  void integrate(double dt) {
    // (group all: no mask to read)
    if (group_is_all())
      integrate<kPass, true>(dt);
    else
      integrate<kPass, false>(dt);
  }
  template <Pass kPass, bool kAll>
  void integrate(double dt) {
    constexpr bool First = kPass != Pass::kSecond;
    constexpr int kKicks = kPass == Pass::kBoth ? 2 : 1;
    Particles& p = *engine_.particles;
    const double dtf = 0.5 * dt;
    const double dtfrot = dtf / kInertia;
    Vec3 *const x = p.x.data(), *const v = p.v.data(), *const omega = p.omega.data();
    const Vec3 *const f = p.f.data(), *const torque = p.torque.data();
    const double *const rmass = p.rmass.data(), *const radius = p.radius.data();
    const int* const mask = p.mask.data();
    const tagint* const body = p.body.data();
    const int bit = groupbit, n = p.nlocal;
    auto update = [&](int i, double dtfm, double dtirotate) {
      if (!(kAll || (mask[i] & bit)) || body[i] >= 0) return;
      for (int k = 0; k < kKicks; ++k)
        v[i] += dtfm * f[i];
      if constexpr (First) x[i] += dt * v[i];
      for (int k = 0; k < kKicks; ++k)
        omega[i] += dtirotate * torque[i];
    };
    // Two particles' 3-vectors are six consecutive doubles: three packed
    // operations with the factors (a, a), (a, b), (b, b).
    using D2 = double __attribute__((vector_size(16)));
    auto kick = [](double* out, const double* in, double a, double b) {
      const D2 c[3] = {D2{a, a}, D2{a, b}, D2{b, b}};
      for (int q = 0; q < 3; ++q) {
        D2 o, g;
        __builtin_memcpy(&o, out + 2 * q, sizeof o);
        __builtin_memcpy(&g, in + 2 * q, sizeof g);
        o += c[q] * g;
        __builtin_memcpy(out + 2 * q, &o, sizeof o);
      }
    };
    int i = 0;
    for (; i + 1 < n; i += 2) {
      const bool free0 = (kAll || (mask[i] & bit)) && body[i] < 0,
                 free1 = (kAll || (mask[i + 1] & bit)) && body[i + 1] < 0;
      if (!free0 && !free1) continue;  // (clump sub-spheres lie together: skipped without the divisions)
      const Eigen::Array2d m(rmass[i], rmass[i + 1]);
      const Eigen::Array2d r(radius[i], radius[i + 1]);
      const Eigen::Array2d dtfm = dtf / m;
      const Eigen::Array2d dtirotate = dtfrot / (r * r * m);
      const bool both = free0 && free1;
      if (both) {
        for (int k = 0; k < kKicks; ++k)
          kick(v[i].data(), f[i].data(), dtfm[0], dtfm[1]);
        if constexpr (First) kick(x[i].data(), v[i].data(), dt, dt);
        for (int k = 0; k < kKicks; ++k)
          kick(omega[i].data(), torque[i].data(), dtirotate[0], dtirotate[1]);
      } else {
        update(i, dtfm[0], dtirotate[0]);
        update(i + 1, dtfm[1], dtirotate[1]);
      }
    }
    for (; i < n; ++i)
      update(i, dtf / rmass[i], dtfrot / (radius[i] * radius[i] * rmass[i]));
  }
};

GRANARY_FIX_STYLE("nve/sphere", FixNveSphere);

}  // namespace granary
