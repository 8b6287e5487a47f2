// Base of particle templates (LIGGGHTS `fix particletemplate/sphere` and
// `fix particletemplate/multisphere`): what one inserted particle looks like.
//
// A template describes a rigid particle made of one or more spheres in its
// body frame (principal axes, origin at the centre of mass). Insertion fixes
// draw particles from templates (through a distribution) and create them; a
// multisphere template's particles are handed to fix multisphere as bodies.
#pragma once

#include <Eigen/Geometry>
#include <random>
#include <string>
#include <vector>

#include "core/vec3.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

/// One particle drawn from a template, before it is placed.
struct TemplateParticle {
  int type = 1;
  double density = 0.0;
  std::vector<Vec3> offsets;     // sphere centres in the body frame [m] (one at 0 for a sphere)
  std::vector<double> radii;     // sphere radii [m]
  double mass = 0.0;             // [kg]
  Vec3 inertia{0, 0, 0};         // principal moments [kg m^2]
  double volume = 0.0;           // solid volume (overlaps counted once) [m^3]
  double bounding_radius = 0.0;  // radius of a sphere about the centre of mass that holds it [m]
  bool multisphere = false;
  // rotation from the body frame to the frame the template was given in (a
  // clump file's coordinates): `orientation template` places it so
  Eigen::Quaterniond frame = Eigen::Quaterniond::Identity();
};

class FixParticleTemplate : public Fix {
 public:
  using Fix::Fix;
  unsigned hooks() const override { return 0; }

  /// Draw one particle (radius or shape distributions use the template's own
  /// random stream, seeded by the script's SEED, identical on every rank).
  virtual TemplateParticle draw() = 0;
  /// Mean solid volume and mass of the particles this template makes.
  virtual double mean_volume() const = 0;
  virtual double mean_mass() const = 0;
  /// Largest bounding radius the template can produce.
  virtual double max_bounding_radius() const = 0;
  virtual bool multisphere() const { return false; }

  int atom_type = 1;
  unsigned seed = 0;

 protected:
  /// The SEED argument (args[3]): a positive integer.
  unsigned parse_seed(const std::string& what) const;
  /// The keywords every template takes, `atom_type T` and `density constant
  /// RHO`, at args[k]: sets atom_type or `density`, leaves k on the last word
  /// used and returns true; returns false for any other keyword.
  bool parse_common_keyword(std::size_t& k, const std::string& what, double& density);
};

/// Implemented by fix multisphere. Insertion decides the same new particles on
/// every rank; each rank creates the sub-spheres it owns (with body id set) and
/// every rank then calls add_body with identical arguments, so the body is
/// known everywhere it is needed.
class BodyRegistrar {
 public:
  virtual ~BodyRegistrar() = default;
  /// Register a rigid body made from `particle`, centre of mass at x_cm, body
  /// frame rotated by q, moving with v and spinning with omega. Sub-sphere k of
  /// the body has global id first_id + k.
  virtual void add_body(tagint body_id, tagint first_id, const TemplateParticle& particle, const Vec3& x_cm,
                        const Eigen::Quaterniond& q, const Vec3& v, const Vec3& omega) = 0;
};

}  // namespace granary
