// compute ID group ke/multisphere: translational kinetic energy of the clumps
// of fix multisphere, sum of 1/2 M v_cm^2 [J] (LIGGGHTS syntax; the group is
// ignored, every clump counts).
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "particles/clumps.h"
#include "core/modify.h"

namespace granary {

namespace {

class ComputeKeMultisphere : public Compute {
 public:
  ComputeKeMultisphere(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID ke/multisphere [region R]";
    if (args.size() == 5 && args[3] == "region") {
      region_id_ = args[4];
      engine.domain->region_or_error(region_id_, "compute " + id + " ke/multisphere");
    } else if (args.size() != 3) {
      throw InputError("wrong arguments for compute " + id + " ke/multisphere; usage: " + usage);
    }
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    // every rank sums every body once its records are current
    Clumps* ms = engine_.clumps;
    if (!ms) throw InputError("compute " + id + " ke/multisphere needs fix multisphere");
    ms->sync_bodies();
    const Bodies& b = ms->bodies();
    double ke = 0.0;
    const Region* region =
        region_id_.empty() ? nullptr
                           : engine_.domain->region_or_error(region_id_, "compute " + id + " ke/multisphere");
    for (int k = 0; k < b.size(); ++k)
      if (!region || region->match(ms->wrapped_centre(k))) ke += b.kinetic_translational(k);
    scalar = ke;
    return scalar;
  }

 private:
  std::string region_id_;  // only clumps whose centre of mass lies in it (all without)
};

}  // namespace

GRANARY_COMPUTE_STYLE("ke/multisphere", ComputeKeMultisphere);

}  // namespace granary
