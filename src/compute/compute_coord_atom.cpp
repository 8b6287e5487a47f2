// compute ID group coord/atom CUTOFF [mix yes|no] [typeN ...]: per particle of
// the group, the number of particles (of any group) whose centre lies closer
// than CUTOFF to its own; with typeN ranges one count per range, with
// mix yes only particles of another type. 0 for particles outside the group.
// Found by a cell list (SphereGrid) over the owned and ghost particles at
// each evaluation, so CUTOFF is bounded by the ghost shell.
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

class ComputeCoordAtom : public Compute {
 public:
  ComputeCoordAtom(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID coord/atom CUTOFF [mix yes|no] [type ranges ...]";
    if (args.size() < 4) throw InputError("compute " + id + " coord/atom: missing cutoff; usage: " + usage);
    cutoff_ = parse_double(args[3], "compute " + id + " coord/atom cutoff");
    if (!(cutoff_ > 0.0))
      throw InputError("compute " + id + " coord/atom: the cutoff must be > 0; usage: " + usage);
    const int ntypes = engine.particles->ntypes;
    for (std::size_t k = 4; k < args.size(); ++k) {
      if (args[k] == "mix") {
        if (k + 1 >= args.size()) throw InputError("compute " + id + " coord/atom: mix needs yes or no");
        mix_ = parse_bool(args[++k], "compute " + id + " coord/atom mix");
      } else {
        int lo = 0, hi = 0;
        parse_type_range(args[k], ntypes, lo, hi);
        ranges_.push_back({lo, hi});
      }
    }
    if (mix_ && ranges_.size() > 1)
      throw InputError("compute " + id +
                       " coord/atom: mix yes counts one number; give no type ranges with it");
    if (ranges_.empty()) ranges_.push_back({1, ntypes});
    peratom_flag = true;
    peratom_cols = ranges_.size() == 1 ? 0 : static_cast<int>(ranges_.size());
  }

  void compute_peratom() override {
    const Particles& p = *engine_.particles;
    require_ghost_reach(cutoff_);
    const int ncol = static_cast<int>(ranges_.size());
    std::vector<std::vector<double>> count(ncol,
                                           std::vector<double>(static_cast<std::size_t>(p.nlocal), 0.0));
    // every particle this rank holds as a sphere of radius cutoff / 2: two
    // overlap when their centres are closer than the cutoff (the ghosts stand
    // for the periodic images, so none are added)
    const double half = 0.5 * cutoff_;
    SphereGrid grid(*engine_.domain, half);
    for (int j = 0; j < p.size(); ++j)
      grid.add(p.x[j], half);
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      grid.visit_overlapping(p.x[i], half, false, [&](int j) {
        if (j == i || (mix_ && p.type[j] == p.type[i])) return false;
        for (int col = 0; col < ncol; ++col)
          if (p.type[j] >= ranges_[col].first && p.type[j] <= ranges_[col].second) count[col][i] += 1.0;
        return false;
      });
    }
    if (peratom_cols == 0) {
      vector_atom = std::move(count[0]);
    } else {
      array_atom = std::move(count);
    }
  }

 private:
  double cutoff_ = 0.0;
  bool mix_ = false;
  std::vector<std::pair<int, int>> ranges_;
};

}  // namespace

GRANARY_COMPUTE_STYLE("coord/atom", ComputeCoordAtom);

}  // namespace granary
