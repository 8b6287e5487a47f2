// compute ID group cluster/atom CUTOFF: per particle of the group, the id of
// its cluster, the smallest particle id among the group's particles linked to
// it by chains of centre distances below CUTOFF; 0 outside the group. The
// labels spread by repeated sweeps over a cell list of the owned and ghost
// particles, the ghosts taking their owners' labels between sweeps, until no
// label changes on any rank (CUTOFF is bounded by the ghost shell).
#include <mpi.h>

#include <cstdio>
#include <vector>

#include "comm/comm.h"
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/utils.h"
#include "domain/domain.h"
#include "geometry/sphere_grid.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeClusterAtom : public Compute {
 public:
  ComputeClusterAtom(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID cluster/atom CUTOFF";
    if (args.size() != 4)
      throw InputError("compute " + id + " cluster/atom takes one value, the cutoff; usage: " + usage);
    cutoff_ = parse_double(args[3], "compute " + id + " cluster/atom cutoff");
    if (!(cutoff_ > 0.0))
      throw InputError("compute " + id + " cluster/atom: the cutoff must be > 0; usage: " + usage);
    peratom_flag = true;
  }

  void compute_peratom() override {
    Particles& p = *engine_.particles;
    require_ghost_reach(cutoff_);
    const int nall = p.size();
    // labels of owned and ghost particles (ids fit a double exactly up to 2^53)
    std::vector<double> label(static_cast<std::size_t>(nall), 0.0);
    for (int i = 0; i < p.nlocal; ++i)
      label[i] = (p.mask[i] & groupbit) ? static_cast<double>(p.id[i]) : 0.0;
    engine_.comm->forward_comm_field(label, 1);
    // the links of each owned group particle to group particles (owned or ghost) within the cutoff
    const double half = 0.5 * cutoff_;
    SphereGrid grid(*engine_.domain, half);
    for (int j = 0; j < nall; ++j)
      grid.add(p.x[j], half);
    std::vector<int> start(static_cast<std::size_t>(p.nlocal) + 1, 0), links;
    for (int i = 0; i < p.nlocal; ++i) {
      start[i] = static_cast<int>(links.size());
      if (label[i] == 0.0) continue;
      grid.visit_overlapping(p.x[i], half, false, [&](int j) {
        if (j != i && label[j] != 0.0 && (p.x[j] - p.x[i]).squaredNorm() < cutoff_ * cutoff_)
          links.push_back(j);
        return false;
      });
    }
    start[p.nlocal] = static_cast<int>(links.size());
    // sweep until no label changes anywhere: each owned particle takes the
    // smallest label among itself and its links; ghosts follow their owners
    while (true) {
      bool changed = false;
      for (bool again = true; again;) {
        again = false;
        for (int i = 0; i < p.nlocal; ++i) {
          for (int k = start[i]; k < start[i + 1]; ++k) {
            const int j = links[k];
            if (label[j] < label[i]) {
              label[i] = label[j];
              again = changed = true;
            } else if (j < p.nlocal && label[i] < label[j]) {
              label[j] = label[i];
              again = changed = true;
            }
          }
        }
      }
      int local = changed ? 1 : 0, any = 0;
      MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_MAX, engine_.world);
      if (!any) break;
      engine_.comm->forward_comm_field(label, 1);
    }
    vector_atom.assign(label.begin(), label.begin() + p.nlocal);
  }

 private:
  double cutoff_ = 0.0;
};

}  // namespace

GRANARY_COMPUTE_STYLE("cluster/atom", ComputeClusterAtom);

}  // namespace granary
