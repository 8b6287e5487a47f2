// compute ID group ke: total translational kinetic energy of the group,
// sum of 1/2 m v^2 over its particles [J].
#include <mpi.h>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "core/registry.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeKE : public Compute {
 public:
  ComputeKE(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID ke [region R]";
    if (args.size() == 5 && args[3] == "region") {
      region_id_ = args[4];
      engine.domain->region_or_error(region_id_, "compute " + id + " ke");
    } else if (args.size() != 3) {
      throw InputError("wrong arguments for compute " + id + " ke; usage: " + usage);
    }
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    const Particles& p = *engine_.particles;
    const Region* region =
        region_id_.empty() ? nullptr : engine_.domain->region_or_error(region_id_, "compute " + id + " ke");
    double local = 0.0;
    for (int i = 0; i < p.nlocal; ++i)
      if ((p.mask[i] & groupbit) && (!region || region->match(p.x[i])))
        local += p.rmass[i] * p.v[i].squaredNorm();
    double all = 0.0;
    MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    scalar = 0.5 * all;
    return scalar;
  }

 private:
  std::string region_id_;  // only particles whose centre lies in it (all without)
};

}  // namespace

GRANARY_COMPUTE_STYLE("ke", ComputeKE);

}  // namespace granary
