// compute ID group erotate/sphere: total rotational kinetic energy of the
// group's free spheres, sum of 1/2 I w^2 with I = 2/5 m r^2 [J]; sub-spheres
// of clumps do not count (as in LIGGGHTS 3.8, measured).
// compute ID group erotate: the same plus the clumps' rotational energy
// (erotate/sphere + erotate/multisphere).
#include "compute/compute.h"
#include "compute/kinetic_energy.h"
#include "core/engine.h"
#include "core/error.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "core/registry.h"

namespace granary {

namespace {

class ComputeERotateSphere : public Compute {
 public:
  ComputeERotateSphere(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID erotate/sphere [region R]";
    if (args.size() == 5 && args[3] == "region") {
      region_id_ = args[4];
      engine.domain->region_or_error(region_id_, "compute " + id + " erotate/sphere");
    } else if (args.size() != 3) {
      throw InputError("wrong arguments for compute " + id + " erotate/sphere; usage: " + usage);
    }
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    const Region* region =
        region_id_.empty() ? nullptr
                           : engine_.domain->region_or_error(region_id_, "compute " + id + " erotate/sphere");
    scalar = kinetic_rotational(engine_, groupbit, region, false);
    return scalar;
  }

 private:
  std::string region_id_;  // only particles whose centre lies in it (all without)
};

class ComputeERotate : public Compute {
 public:
  ComputeERotate(Engine& engine, const Args& args) : Compute(engine, args) {
    if (args.size() != 3)
      throw InputError("wrong arguments for compute " + id + " erotate; usage: compute ID group-ID erotate");
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    scalar = kinetic_rotational(engine_, groupbit, nullptr, true);
    return scalar;
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("erotate/sphere", ComputeERotateSphere);
GRANARY_COMPUTE_STYLE("erotate", ComputeERotate);

}  // namespace granary
