// Kinetic energies as LIGGGHTS counts them (compute ke, erotate,
// erotate/sphere and the thermo keyword ke): free particles by their own mass,
// velocity and spin, clumps of fix multisphere as bodies (their sub-spheres do
// not count one by one).
#pragma once

namespace granary {

class Engine;
class Region;

/// Sum over all ranks of 1/2 m v^2 of the free particles of `groupbit` whose
/// centre lies in `region` (all without) and 1/2 M v_cm^2 of the clumps whose
/// first sub-sphere is in the group and whose centre of mass (wrapped) lies
/// in the region (collective).
double kinetic_translational(const Engine& e, int groupbit, const Region* region);

/// Sum over all ranks of 1/2 (2/5 m r^2) w^2 of the free spheres of `groupbit`
/// in `region` and, with clumps_too, 1/2 w.L of the clumps chosen as above
/// (collective).
double kinetic_rotational(const Engine& e, int groupbit, const Region* region, bool clumps_too);

}  // namespace granary
