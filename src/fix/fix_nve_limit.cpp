// fix ID group nve/limit absolute XMAX | radius_ratio RATIO
//
// Velocity-Verlet integration of position and velocity (not of spin, as in
// LIGGGHTS) in which no particle moves farther than XMAX [m] (absolute) or
// RATIO times its radius (radius_ratio) in one step: after each half-kick, a
// velocity whose magnitude exceeds limit/dt is scaled down to it. The scalar
// is the number of half-kicks limited so far in this run (over all ranks).
// Spheres of clumps are left to fix multisphere.
#include <mpi.h>

#include <cmath>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage = "fix ID group nve/limit absolute XMAX | radius_ratio RATIO  (XMAX in m)";

class FixNveLimit : public Fix {
 public:
  FixNveLimit(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 5, 5, kUsage);
    if (args[3] == "absolute") {
      relative_ = false;
    } else if (args[3] == "radius_ratio") {
      relative_ = true;
    } else {
      const std::string hint = did_you_mean(args[3], {"absolute", "radius_ratio"});
      throw InputError("unknown fix nve/limit style '" + args[3] + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + kUsage);
    }
    xmax_ = parse_double(args[4], "the limit of fix nve/limit");
    if (!(xmax_ > 0.0)) throw InputError("fix nve/limit: the limit must be positive (got " + args[4] + ")");
    time_integrate = true;
    scalar_flag = true;
  }

  unsigned hooks() const override { return INITIAL_INTEGRATE | FINAL_INTEGRATE; }

  void init() override { count_ = 0; }  // counted per run

  void initial_integrate() override { integrate(true); }
  void final_integrate() override { integrate(false); }

  double compute_scalar() override {
    long long all = 0;
    MPI_Allreduce(&count_, &all, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
    return static_cast<double>(all);
  }

 private:
  void integrate(bool first) {
    Particles& p = *engine_.particles;
    const double dt = engine_.update->dt;
    const double dtf = 0.5 * dt;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit) || p.body[i] >= 0) continue;
      p.v[i] += dtf / p.rmass[i] * p.f[i];
      const double vmax = (relative_ ? xmax_ * p.radius[i] : xmax_) / dt;
      const double v2 = p.v[i].squaredNorm();
      if (v2 > vmax * vmax) {
        ++count_;
        p.v[i] *= vmax / std::sqrt(v2);
      }
      if (first) p.x[i] += dt * p.v[i];
    }
  }

  bool relative_ = false;
  double xmax_ = 0.0;
  long long count_ = 0;
};

}  // namespace

GRANARY_FIX_STYLE("nve/limit", FixNveLimit);

}  // namespace granary
