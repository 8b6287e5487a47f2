// compute ID group erotate/multisphere: rotational kinetic energy of the
// clumps of fix multisphere, sum of 1/2 w.L [J] (LIGGGHTS syntax; the group is
// ignored, every clump counts).
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "fix/fix_multisphere.h"
#include "fix/modify.h"

namespace granary {

namespace {

class ComputeERotateMultisphere : public Compute {
 public:
  ComputeERotateMultisphere(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group-ID erotate/multisphere");
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    const FixMultisphere* ms = FixMultisphere::find(*engine_.modify);
    if (!ms) throw InputError("compute " + id + " erotate/multisphere needs fix multisphere");
    const Bodies& b = ms->bodies();
    double e = 0.0;
    for (int k = 0; k < b.size(); ++k)
      e += b.kinetic_rotational(k);
    scalar = e;
    return scalar;
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("erotate/multisphere", ComputeERotateMultisphere);

}  // namespace granary
