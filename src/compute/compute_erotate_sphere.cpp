// compute ID group erotate/sphere: total rotational kinetic energy of the
// group's free spheres, sum of 1/2 I w^2 with I = 2/5 m r^2 [J]; sub-spheres
// of clumps do not count (as in LIGGGHTS 3.8, measured).
// compute ID group erotate: the same plus the clumps' rotational energy
// (erotate/sphere + erotate/multisphere).
#include <mpi.h>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "core/registry.h"
#include "particles/clumps.h"
#include "particles/particles.h"

namespace granary {

namespace {

/// Sum of 1/2 I w^2 over the free spheres of `groupbit` (in `region` if set), all ranks.
double free_sphere_erotate(const Engine& e, int groupbit, const Region* region) {
  const Particles& p = *e.particles;
  double local = 0.0;
  for (int i = 0; i < p.nlocal; ++i) {
    if ((p.mask[i] & groupbit) && p.body[i] < 0 && (!region || region->match(p.x[i]))) {
      local += p.rmass[i] * p.radius[i] * p.radius[i] * p.omega[i].squaredNorm();
    }
  }
  double all = 0.0;
  MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, e.world);
  return 0.5 * 0.4 * all;  // 1/2 * (2/5 m r^2) * w^2
}

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
    scalar = free_sphere_erotate(engine_, groupbit, region);
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
    double e = free_sphere_erotate(engine_, groupbit, nullptr);
    if (Clumps* ms = engine_.clumps) {
      ms->sync_bodies();  // every rank sums every body once its records are current
      const Bodies& b = ms->bodies();
      for (int k = 0; k < b.size(); ++k)
        e += b.kinetic_rotational(k);
    }
    scalar = e;
    return scalar;
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("erotate/sphere", ComputeERotateSphere);
GRANARY_COMPUTE_STYLE("erotate", ComputeERotate);

}  // namespace granary
