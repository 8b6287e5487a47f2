// compute ID group contact/atom (also contact/atom/gran and coord/gran): per
// particle of the group, the number of particles it touches (centres closer
// than the sum of the radii), from the current neighbour list; 0 for
// particles outside the group. Spheres of one clump do not count each other.
#include <vector>

#include "comm/comm.h"
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/registry.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeContactAtom : public Compute {
 public:
  ComputeContactAtom(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group " + args[2]);
    peratom_flag = true;
  }

  void compute_peratom() override {
    const Particles& p = *engine_.particles;
    const Neighbor& nb = *engine_.neighbor;
    if (nb.offset.size() != static_cast<std::size_t>(p.nlocal) + 1)
      throw InputError("compute " + id + " (" + style +
                       ") counts contacts from the neighbour lists, which are built by a run: use it during "
                       "a run, or after `run 0` when particles were added or deleted since the last run");
    // with newton on, a pair of an owned particle and a ghost is listed on one
    // rank only: both counts are made there and the ghost's is sent back
    const bool newton = engine_.force->newton_pair;
    std::vector<double> count(static_cast<std::size_t>(p.size()), 0.0);
    for (int i = 0; i < p.nlocal; ++i) {
      for (int k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        const int j = nb.neigh[k];
        const double rsum = p.radius[i] + p.radius[j];
        if ((p.x[i] - p.x[j]).squaredNorm() >= rsum * rsum) continue;
        count[i] += 1.0;
        if (j < p.nlocal || newton) count[j] += 1.0;
      }
    }
    if (newton) engine_.comm->reverse_comm_field(count, 1);
    vector_atom.assign(p.nlocal, 0.0);
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & groupbit) vector_atom[i] = count[i];
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("contact/atom", ComputeContactAtom);
GRANARY_COMPUTE_STYLE("contact/atom/gran", ComputeContactAtom);
GRANARY_COMPUTE_STYLE("coord/gran", ComputeContactAtom);

}  // namespace granary
