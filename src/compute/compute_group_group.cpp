// compute ID group-ID group/group GROUP2-ID [pair yes] [kspace no]
//     [boundary yes|no] [molecule off]
// (LAMMPS/LIGGGHTS syntax): the total force of the granular pair contacts
// between the particles of GROUP2 and those of group-ID, on group-ID, as a
// global vector (fx, fy, fz). A contact of two particles that are both in
// both groups counts both ways (its forces cancel). The contacts and their
// forces are those of compute pair/gran/local (the granular pair style's, at
// the current state). See doc/computes/group_group.md.
#include <mpi.h>

#include <algorithm>

#include "compute/compute_pair_gran_local.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/groups.h"
#include "particles/particles.h"

namespace granary {

namespace {

// compute pair/gran/local of every contact, with the force columns only
Args local_args(const Args& args) {
  if (args.size() < 4)
    throw InputError(
        "compute group/group needs the second group; usage: compute ID group-ID group/group "
        "GROUP2-ID [pair yes] [kspace no] [boundary yes|no] [molecule off]");
  return {args[0], "all", "pair/gran/local", "force"};
}

class ComputeGroupGroup : public ComputePairGranLocal {
 public:
  ComputeGroupGroup(Engine& engine, const Args& args) : ComputePairGranLocal(engine, local_args(args)) {
    style = "group/group";
    local_flag = false;
    const std::string where = "compute " + id + " group/group";
    bit1_ = engine.groups->bitmask(engine.groups->find_or_error(args[1], where));
    bit2_ = engine.groups->bitmask(engine.groups->find_or_error(args[3], where + " (the second group)"));
    for (std::size_t k = 4; k < args.size(); k += 2) {
      const std::string& w = args[k];
      if (k + 1 >= args.size()) throw InputError(where + ": '" + w + "' needs a value");
      const std::string& v = args[k + 1];
      if (w == "pair") {
        if (v != "yes")
          throw InputError(where + ": pair no leaves nothing to sum (granular contacts are pairs)");
      } else if (w == "kspace" || w == "boundary") {
        if (w == "kspace" && v != "no")
          throw InputError(where + ": kspace yes: Granary has no long-range forces");
        if (w == "boundary" && v != "yes" && v != "no")
          throw InputError(where + ": boundary takes yes or no");
      } else if (w == "molecule") {
        if (v != "off") throw InputError(where + ": molecule " + v + ": Granary has no molecules");
      } else {
        throw InputError(where + ": unknown keyword '" + w + "' (pair, kspace, boundary, molecule)");
      }
    }
    size_vector = 3;
  }

  void compute_vector() override {
    compute_local();
    const Particles& p = *engine_.particles;
    const Layout L = layout();
    const int stride = std::max(1, size_local_cols);
    double f[3] = {0, 0, 0}, all[3];
    for (std::size_t r = 0; r < row_i.size(); ++r) {
      const int i = row_i[r], j = row_j[r];
      const double* force = &array_local[r * stride + L.force];  // on i, from j
      double sign = 0.0;
      if ((p.mask[i] & bit1_) && (p.mask[j] & bit2_)) sign += 1.0;
      if ((p.mask[j] & bit1_) && (p.mask[i] & bit2_)) sign -= 1.0;
      for (int d = 0; d < 3; ++d)
        f[d] += sign * force[d];
    }
    MPI_Allreduce(f, all, 3, MPI_DOUBLE, MPI_SUM, engine_.world);
    vector.assign(all, all + 3);
  }

 private:
  int bit1_ = 1, bit2_ = 1;
};

}  // namespace

GRANARY_COMPUTE_STYLE("group/group", ComputeGroupGroup);

}  // namespace granary
