// compute ID group ke/multisphere: translational kinetic energy of the clumps
// of fix multisphere, sum of 1/2 M v_cm^2 [J] (LIGGGHTS syntax; the group is
// ignored, every clump counts).
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "fix/fix_multisphere.h"
#include "fix/modify.h"

namespace granary {

namespace {

class ComputeKeMultisphere : public Compute {
 public:
  ComputeKeMultisphere(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group-ID ke/multisphere");
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    // bodies are replicated on every rank: no communication needed
    const FixMultisphere* ms = FixMultisphere::find(*engine_.modify);
    if (!ms) throw InputError("compute " + id + " ke/multisphere needs fix multisphere");
    const Bodies& b = ms->bodies();
    double ke = 0.0;
    for (int k = 0; k < b.size(); ++k)
      ke += b.kinetic_translational(k);
    scalar = ke;
    return scalar;
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("ke/multisphere", ComputeKeMultisphere);

}  // namespace granary
