// compute ID group com: the group's centre of mass (x, y, z) from the
// positions unwrapped across periodic boundaries (image flags), a global
// vector of 3 [m]; (0, 0, 0) for an empty group. compute ID group gyration:
// the radius of gyration Rg = sqrt(sum m |xu - xcm|^2 / M) as the scalar and
// the tensor sum m (xu - xcm)_a (xu - xcm)_b / M as a vector of 6 (xx, yy,
// zz, xy, xz, yz) [m, m^2].
#include <mpi.h>

#include <cmath>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/groups.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeCOM : public Compute {
 public:
  ComputeCOM(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group-ID com");
    size_vector = 3;
    vector.assign(3, 0.0);
  }

  void compute_vector() override {
    const Vec3 c = engine_.groups->xcm(igroup);
    for (int d = 0; d < 3; ++d)
      vector[d] = c[d];
  }
};

class ComputeGyration : public Compute {
 public:
  ComputeGyration(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group-ID gyration");
    scalar_flag = true;
    size_vector = 6;
    vector.assign(6, 0.0);
  }

  double compute_scalar() override {
    compute_vector();
    scalar = std::sqrt(vector[0] + vector[1] + vector[2]);
    return scalar;
  }

  void compute_vector() override {
    const Particles& p = *engine_.particles;
    const Vec3 c = engine_.groups->xcm(igroup);
    double local[7] = {0, 0, 0, 0, 0, 0, 0};
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const Vec3 r = engine_.groups->unwrapped(i) - c;
      const double m = p.rmass[i];
      local[0] += m * r[0] * r[0];
      local[1] += m * r[1] * r[1];
      local[2] += m * r[2] * r[2];
      local[3] += m * r[0] * r[1];
      local[4] += m * r[0] * r[2];
      local[5] += m * r[1] * r[2];
      local[6] += m;
    }
    double all[7];
    MPI_Allreduce(local, all, 7, MPI_DOUBLE, MPI_SUM, engine_.world);
    for (int k = 0; k < 6; ++k)
      vector[k] = all[6] > 0.0 ? all[k] / all[6] : 0.0;
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("com", ComputeCOM);
GRANARY_COMPUTE_STYLE("gyration", ComputeGyration);

}  // namespace granary
