// compute ID group ke: total translational kinetic energy of the group [J]:
// 1/2 m v^2 of its free particles plus 1/2 M v_cm^2 of its clumps.

#include "compute/compute.h"
#include "compute/kinetic_energy.h"
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
    const Region* region =
        region_id_.empty() ? nullptr : engine_.domain->region_or_error(region_id_, "compute " + id + " ke");
    scalar = kinetic_translational(engine_, groupbit, region);
    return scalar;
  }

 private:
  std::string region_id_;  // only particles whose centre lies in it (all without)
};

}  // namespace

GRANARY_COMPUTE_STYLE("ke", ComputeKE);

}  // namespace granary
