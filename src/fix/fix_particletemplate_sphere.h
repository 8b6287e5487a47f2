// fix ID group particletemplate/sphere SEED [atom_type T] [density constant RHO]
//     [radius constant R | radius uniform LO HI] [volume_limit V] [relative no]
//
// A particle template for spheres (LIGGGHTS syntax): every particle drawn from
// it is one sphere of type T and density RHO. Its radius is constant (as in
// LIGGGHTS) or, as a Granary addition, uniformly distributed in [LO, HI]. The
// radius stream is seeded by SEED and identical on every rank.
#pragma once

#include <random>
#include <string>

#include "fix/fix_particle_template.h"

namespace granary {

class FixParticleTemplateSphere : public FixParticleTemplate {
 public:
  FixParticleTemplateSphere(Engine& engine, const Args& args);

  TemplateParticle draw() override;
  double mean_volume() const override;
  double mean_mass() const override { return density_ * mean_volume(); }
  double max_bounding_radius() const override { return uniform_ ? radius_hi_ : radius_; }

  void init() override;
  void pack_restart(std::string& out) const override;
  void unpack_restart(const std::string& in) override;

  double density() const { return density_; }
  bool uniform_radius() const { return uniform_; }

  /// A sphere of radius r and density rho as a template particle.
  static TemplateParticle sphere(int type, double r, double rho);

 private:
  double density_ = 1.0;
  double radius_ = 1.0;   // constant radius
  bool uniform_ = false;  // radius uniform LO HI
  double radius_lo_ = 0.0, radius_hi_ = 0.0;
  double volume_limit_ = 1e-12;
  std::mt19937_64 gen_;
};

}  // namespace granary
