// compute ID group count/region REGION: number of the group's particles whose
// centre lies in the region (a global scalar). Granary's own style; LIGGGHTS
// scripts get the same number from the group function count(group,region).
#include <mpi.h>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeCountRegion : public Compute {
 public:
  ComputeCountRegion(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 4, 4, "compute ID group-ID count/region REGION");
    region_id_ = args[3];
    engine.domain->region_or_error(region_id_, "compute " + id);
    scalar_flag = true;
    extensive = true;
  }

  void init() override { engine_.domain->region_or_error(region_id_, "compute " + id); }

  double compute_scalar() override {
    // looked up every time: the region may have been deleted and redefined
    const Region* region = engine_.domain->region_or_error(region_id_, "compute " + id);
    const Particles& p = *engine_.particles;
    long long local = 0;
    for (int i = 0; i < p.nlocal; ++i)
      if ((p.mask[i] & groupbit) && region->match(p.x[i])) ++local;
    long long all = 0;
    MPI_Allreduce(&local, &all, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
    scalar = static_cast<double>(all);
    return scalar;
  }

 private:
  std::string region_id_;
};

}  // namespace

GRANARY_COMPUTE_STYLE("count/region", ComputeCountRegion);

}  // namespace granary
