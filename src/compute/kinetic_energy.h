// Translational kinetic energy as LIGGGHTS counts it (compute ke and the
// thermo keyword ke): free particles by their own mass and velocity, clumps
// of fix multisphere by their mass and centre-of-mass velocity (their
// sub-spheres do not count one by one).
#pragma once

namespace granary {

class Engine;
class Region;

/// Sum over all ranks of 1/2 m v^2 of the free particles of `groupbit` whose
/// centre lies in `region` (all without) and 1/2 M v_cm^2 of the clumps whose
/// first sub-sphere is in the group and whose centre of mass (wrapped) lies
/// in the region (collective).
double kinetic_translational(const Engine& e, int groupbit, const Region* region);

}  // namespace granary
