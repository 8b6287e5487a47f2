// compute ID group erotate/multisphere: rotational kinetic energy of the
// clumps of fix multisphere, sum of 1/2 w.L [J] (LIGGGHTS syntax; the group is
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

class ComputeERotateMultisphere : public Compute {
 public:
  ComputeERotateMultisphere(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID erotate/multisphere [region R]";
    if (args.size() == 5 && args[3] == "region") {
      region_id_ = args[4];
      engine.domain->region_or_error(region_id_, "compute " + id + " erotate/multisphere");
    } else if (args.size() != 3) {
      throw InputError("wrong arguments for compute " + id + " erotate/multisphere; usage: " + usage);
    }
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    Clumps* ms = engine_.clumps;
    if (!ms) throw InputError("compute " + id + " erotate/multisphere needs fix multisphere");
    ms->sync_bodies();  // every rank sums every body once its records are current
    const Bodies& b = ms->bodies();
    double e = 0.0;
    const Region* region = region_id_.empty() ? nullptr
                                              : engine_.domain->region_or_error(
                                                    region_id_, "compute " + id + " erotate/multisphere");
    for (int k = 0; k < b.size(); ++k)
      if (!region || region->match(ms->wrapped_centre(k))) e += b.kinetic_rotational(k);
    scalar = e;
    return scalar;
  }

 private:
  std::string region_id_;  // only clumps whose centre of mass lies in it (all without)
};

}  // namespace

GRANARY_COMPUTE_STYLE("erotate/multisphere", ComputeERotateMultisphere);

}  // namespace granary
