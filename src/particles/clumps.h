// The engine's rigid clumps as the rest of the code sees them: Engine::clumps,
// a typed handle that is set while a fix multisphere exists (there is at most
// one) and null otherwise. Computes, dumps, restart files, clog detection,
// insertion and the particle commands reach the bodies through it instead of
// searching the fix list.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "core/vec3.h"
#include "particles/bodies.h"

namespace granary {

class BodyRegistrar;
struct TemplateParticle;

/// Implemented by outputs whose size follows the number of bodies (compute
/// multisphere): fix multisphere tells them whenever bodies come or go.
class BodyOutput {
 public:
  virtual ~BodyOutput() = default;
  virtual void bodies_changed(int nbodies) = 0;
};

class Clumps {
 public:
  virtual ~Clumps() = default;
  /// The body records. The dynamic state of a body is current on the ranks
  /// that own one of its sub-spheres; call sync_bodies() first (collective)
  /// to read it for every body.
  virtual const Bodies& bodies() const = 0;
  virtual Bodies& bodies() = 0;
  /// Make every rank's record of every body current (collective).
  virtual void sync_bodies() = 0;
  /// Body centre wrapped into the periodic box [m].
  virtual Vec3 wrapped_centre(int b) const = 0;
  /// Remove the clumps with these body ids, their owned sub-spheres and
  /// everything keyed on them (collective, same ids on every rank, no
  /// ghosts). Returns the number of particles removed on this rank.
  virtual long long remove_bodies(const std::vector<tagint>& ids) = 0;
  /// Create one clump from `particle` with its centre of mass at x
  /// (collective). Returns the body id.
  virtual tagint create_clump(const TemplateParticle& particle, const Vec3& x, const Eigen::Quaterniond& q,
                              const Vec3& v, const Vec3& omega) = 0;
  /// Where insertion registers the bodies it creates.
  virtual BodyRegistrar& registrar() = 0;
};

}  // namespace granary
