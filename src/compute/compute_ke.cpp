// compute ID group ke: total translational kinetic energy of the group,
// sum of 1/2 m v^2 over its particles [J].
#include <mpi.h>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/registry.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeKE : public Compute {
 public:
  ComputeKE(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group-ID ke");
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    const Particles& p = *engine_.particles;
    double local = 0.0;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & groupbit) local += p.rmass[i] * p.v[i].squaredNorm();
    double all = 0.0;
    MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    scalar = 0.5 * all;
    return scalar;
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("ke", ComputeKE);

}  // namespace granary
