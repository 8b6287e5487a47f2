// Kinetic energies as LIGGGHTS counts them (compute ke, erotate, erotate/sphere
// and the thermo keyword ke): free particles one by one, clumps of fix
// multisphere as bodies.
#include "compute/kinetic_energy.h"

#include <mpi.h>

#include "core/engine.h"
#include "domain/region.h"
#include "particles/clumps.h"
#include "particles/particles.h"

namespace granary {

namespace {

// Sum over all ranks of free(i) for the free particles of the group whose
// centre lies in the region, and (with clumps_too) of body(k) for the clumps
// whose first sub-sphere is in the group and whose wrapped centre of mass is
// in the region. A clump counts once, on the rank that owns its first
// sub-sphere, whose record of the body is current (it advances the body).
template <class Free, class Body>
double sum_energy(const Engine& e, int groupbit, const Region* region, bool clumps_too, Free free,
                  Body body) {
  const Particles& p = *e.particles;
  const Clumps* clumps = e.clumps;
  double local = 0.0;
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & groupbit)) continue;
    if (p.body[i] < 0 || !clumps) {
      if (!region || region->match(p.x[i])) local += free(i);
      continue;
    }
    if (!clumps_too) continue;
    const Bodies& b = clumps->bodies();
    const int k = b.find(p.body[i]);
    if (k < 0 || p.id[i] != b.first_id[k]) continue;
    if (!region || region->match(clumps->wrapped_centre(k))) local += body(b, k);
  }
  double all = 0.0;
  MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, e.world);
  return all;
}

}  // namespace

double kinetic_translational(const Engine& e, int groupbit, const Region* region) {
  const Particles& p = *e.particles;
  return sum_energy(
      e, groupbit, region, true, [&](int i) { return 0.5 * p.rmass[i] * p.v[i].squaredNorm(); },
      [](const Bodies& b, int k) { return b.kinetic_translational(k); });
}

double kinetic_rotational(const Engine& e, int groupbit, const Region* region, bool clumps_too) {
  const Particles& p = *e.particles;
  // 1/2 (2/5 m r^2) w^2 of a solid sphere
  return sum_energy(
      e, groupbit, region, clumps_too,
      [&](int i) { return 0.2 * p.rmass[i] * p.radius[i] * p.radius[i] * p.omega[i].squaredNorm(); },
      [](const Bodies& b, int k) { return b.kinetic_rotational(k); });
}

}  // namespace granary
