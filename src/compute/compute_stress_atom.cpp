// compute ID group-ID stress/atom [ke] [pair] [bond ... fix virial]
// (LAMMPS/LIGGGHTS syntax): the per-atom stress tensor times volume
// (xx, yy, zz, xy, xz, yz) [N m]:
//   S_ab = -(m v_a v_b + 1/2 sum over the atom's contacts of (x_i - x_j)_a F_ij_b)
// with F_ij the granular pair force on i from j (each contact's virial shared
// equally by its two particles). Keywords choose the terms: ke, pair (both by
// default); bond, angle, dihedral, improper, kspace, fix add nothing in
// Granary (no such forces), virial = pair. Wall contacts are not included.
// See doc/computes/stress_atom.md.
#include <mpi.h>

#include <algorithm>
#include <string>

#include "comm/comm.h"
#include "compute/compute_pair_gran_local.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/groups.h"
#include "particles/particles.h"

namespace granary {

namespace {

Args contact_args(const Args& args) {
  if (args.size() < 3) throw InputError("usage: compute ID group-ID stress/atom [ke] [pair] [virial]");
  return {args[0], "all", "pair/gran/local", "force"};
}

class ComputeStressAtom : public ComputePairGranLocal {
 public:
  ComputeStressAtom(Engine& engine, const Args& args) : ComputePairGranLocal(engine, contact_args(args)) {
    style = "stress/atom";
    local_flag = false;
    igroup_ = engine.groups->find_or_error(args[1], "compute " + args[0] + " stress/atom");
    if (args.size() > 3) {
      ke_ = pair_ = false;
      for (std::size_t k = 3; k < args.size(); ++k) {
        const std::string& w = args[k];
        if (w == "ke")
          ke_ = true;
        else if (w == "pair" || w == "virial")
          pair_ = true;
        else if (w == "bond" || w == "angle" || w == "dihedral" || w == "improper" || w == "kspace" ||
                 w == "fix")
          continue;  // no such forces in Granary: they add nothing
        else
          throw InputError("compute " + id + " stress/atom: unknown keyword '" + w +
                           "' (ke, pair, bond, angle, dihedral, improper, kspace, fix, virial)");
      }
    }
    peratom_flag = true;
    peratom_cols = 6;
  }

  void compute_peratom() override {
    Particles& p = *engine_.particles;
    const int n = p.size();
    std::vector<double> s(6 * static_cast<std::size_t>(n), 0.0);  // virial W_ab, then -(ke + W)
    if (pair_) {
      compute_local();
      const Layout L = layout();
      const int stride = std::max(1, size_local_cols);
      for (std::size_t r = 0; r < row_i.size(); ++r) {
        const int i = row_i[r], j = row_j[r];
        const double* f = &array_local[r * stride + L.force];  // on i, from j
        const Vec3 d = p.x[i] - p.x[j];
        const double w[6] = {0.5 * d[0] * f[0], 0.5 * d[1] * f[1], 0.5 * d[2] * f[2],
                             0.5 * d[0] * f[1], 0.5 * d[0] * f[2], 0.5 * d[1] * f[2]};
        for (int c = 0; c < 6; ++c) {
          s[6 * static_cast<std::size_t>(i) + c] += w[c];
          s[6 * static_cast<std::size_t>(j) + c] += w[c];
        }
      }
      // the halves of contacts with ghosts go to the ghosts' owners
      engine_.comm->reverse_comm_field(s, 6);
    }
    array_atom.assign(6, std::vector<double>(p.nlocal, 0.0));
    const int bit = 1 << igroup_;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & bit)) continue;
      double k[6] = {0, 0, 0, 0, 0, 0};
      if (ke_) {
        const Vec3& v = p.v[i];
        const double m = p.rmass[i];
        k[0] = m * v[0] * v[0];
        k[1] = m * v[1] * v[1];
        k[2] = m * v[2] * v[2];
        k[3] = m * v[0] * v[1];
        k[4] = m * v[0] * v[2];
        k[5] = m * v[1] * v[2];
      }
      for (int c = 0; c < 6; ++c)
        array_atom[c][i] = -(k[c] + s[6 * static_cast<std::size_t>(i) + c]);
    }
  }

 private:
  int igroup_ = 0;
  bool ke_ = true, pair_ = true;
};

}  // namespace

GRANARY_COMPUTE_STYLE("stress/atom", ComputeStressAtom);

}  // namespace granary
