// fix particletemplate/multisphere: a rigid clump of spheres (LIGGGHTS syntax).
//
//   fix ID group particletemplate/multisphere SEED atom_type T density constant RHO
//       nspheres N ntry M spheres file FILE [scale S] | spheres x1 y1 z1 r1 ... type MT
//       [mass M] [inertia_tensor Ixx Ixy Ixz Iyy Iyz Izz] [use_volume | use_density]
//
// Mass, volume, centre of mass and inertia tensor are integrated once
// (mass_properties.h, about M sample points) and the sphere offsets are moved
// into the principal frame, moments ascending. See
// doc/fixes/particletemplate_multisphere.md.
#pragma once

#include "fix/fix_particle_template.h"
#include "geometry/mass_properties.h"

namespace granary {

class FixParticleTemplateMultisphere : public FixParticleTemplate {
 public:
  FixParticleTemplateMultisphere(Engine& engine, const Args& args);

  void init() override;
  TemplateParticle draw() override { return particle_; }
  double mean_volume() const override { return particle_.volume; }
  double mean_mass() const override { return particle_.mass; }
  double max_bounding_radius() const override { return particle_.bounding_radius; }
  bool multisphere() const override { return true; }

  const TemplateParticle& particle() const { return particle_; }
  const MassProperties& properties() const { return props_; }
  /// Sphere centres and radii as given (after scale), in the input frame.
  const std::vector<Vec3>& input_centres() const { return centres_; }
  /// Rotation from the body (principal) frame to the input frame, and the centre of mass in the input frame.
  const Eigen::Matrix3d& axes() const { return axes_; }
  const Vec3& centre() const { return centre_; }
  int clump_type = 1;  // LIGGGHTS' multisphere type `type MT`

 private:
  void read_file(const std::string& path, double scale, std::vector<double>& values) const;
  TemplateParticle particle_;
  MassProperties props_;
  std::vector<Vec3> centres_;
  Eigen::Matrix3d axes_ = Eigen::Matrix3d::Identity();
  Vec3 centre_{0, 0, 0};
};

}  // namespace granary
