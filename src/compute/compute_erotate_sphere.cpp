// compute ID group erotate/sphere: total rotational kinetic energy of the
// group's spheres, sum of 1/2 I w^2 with I = 2/5 m r^2 [J].
#include <mpi.h>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/registry.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeERotateSphere : public Compute {
 public:
  ComputeERotateSphere(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group-ID erotate/sphere");
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    const Particles& p = *engine_.particles;
    double local = 0.0;
    for (int i = 0; i < p.nlocal; ++i) {
      if (p.mask[i] & groupbit) {
        local += p.rmass[i] * p.radius[i] * p.radius[i] * p.omega[i].squaredNorm();
      }
    }
    double all = 0.0;
    MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    scalar = 0.5 * 0.4 * all;  // 1/2 * (2/5 m r^2) * w^2
    return scalar;
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("erotate/sphere", ComputeERotateSphere);

}  // namespace granary
