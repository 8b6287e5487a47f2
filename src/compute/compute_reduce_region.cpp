// compute ID group reduce/region REGION MODE inputs...: compute reduce over
// the group's particles whose centre lies in REGION (see compute_reduce.h).
#include "compute/compute_reduce.h"
#include "core/registry.h"

namespace granary {

namespace {

class ComputeReduceRegion : public ComputeReduce {
 public:
  ComputeReduceRegion(Engine& engine, const Args& args) : ComputeReduce(engine, args, true) {}
};

}  // namespace

GRANARY_COMPUTE_STYLE("reduce/region", ComputeReduceRegion);

}  // namespace granary
