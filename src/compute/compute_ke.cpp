// compute ID group ke: total translational kinetic energy of the group [J]:
// 1/2 m v^2 of its free particles plus 1/2 M v_cm^2 of its clumps.
#include <mpi.h>

#include "compute/compute.h"
#include "compute/kinetic_energy.h"
#include "core/engine.h"
#include "core/error.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "core/registry.h"
#include "particles/clumps.h"
#include "particles/particles.h"

namespace granary {

double kinetic_translational(const Engine& e, int groupbit, const Region* region) {
  const Particles& p = *e.particles;
  const Clumps* clumps = e.clumps;
  double local = 0.0;
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & groupbit)) continue;
    if (p.body[i] < 0 || !clumps) {
      if (!region || region->match(p.x[i])) local += 0.5 * p.rmass[i] * p.v[i].squaredNorm();
      continue;
    }
    // a clump counts once, on the rank that owns its first sub-sphere (whose
    // record of the body is current: it advances the body)
    const Bodies& b = clumps->bodies();
    const int k = b.find(p.body[i]);
    if (k < 0 || p.id[i] != b.first_id[k]) continue;
    if (!region || region->match(clumps->wrapped_centre(k))) local += b.kinetic_translational(k);
  }
  double all = 0.0;
  MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, e.world);
  return all;
}

namespace {

class ComputeKE : public Compute {
 public:
  ComputeKE(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID ke [region R]";
    if (args.size() == 5 && args[3] == "region") {
      region_id_ = args[4];
      engine.domain->region_or_error(region_id_, "compute " + id + " ke");
    } else if (args.size() != 3) {
      throw InputError("wrong arguments for compute " + id + " ke; usage: " + usage);
    }
    scalar_flag = true;
    extensive = true;
  }

  double compute_scalar() override {
    const Region* region =
        region_id_.empty() ? nullptr : engine_.domain->region_or_error(region_id_, "compute " + id + " ke");
    scalar = kinetic_translational(engine_, groupbit, region);
    return scalar;
  }

 private:
  std::string region_id_;  // only particles whose centre lies in it (all without)
};

}  // namespace

GRANARY_COMPUTE_STYLE("ke", ComputeKE);

}  // namespace granary
