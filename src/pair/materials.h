// Material table: mixed contact parameters for every pair of atom types, read
// from the fix property/global entries of a LIGGGHTS script.
#pragma once

#include <string>
#include <vector>

#include "contact/contact_model.h"
#include "pair/pair.h"

namespace granary {

class Engine;

class MaterialTable {
 public:
  /// Read youngsModulus, poissonsRatio (peratomtype), coefficientRestitution,
  /// coefficientFriction, coefficientRollingFriction (peratomtypepair) and
  /// characteristicVelocity (scalar, Hooke only); with hooke/stiffness and
  /// hertz/stiffness kn, kt, gamman, gammat (peratomtypepair; gamman_abs and
  /// gammat_abs with absolute_damping on). `user` names the style for messages.
  void build(Engine& engine, const contact::ModelSpec& spec, const std::string& user);
  const contact::PairMaterial& operator()(int ti, int tj) const { return table_[ti * stride_ + tj]; }
  int ntypes() const { return stride_ - 1; }
  double youngs(int t) const { return youngs_[t]; }
  double poisson(int t) const { return poisson_[t]; }

 private:
  int stride_ = 0;
  std::vector<contact::PairMaterial> table_;
  std::vector<double> youngs_, poisson_;
};

/// Contact time scales over the owned particles (collective). Rayleigh time
/// pi r sqrt(rho/G) / (0.1631 nu + 0.8766) with G = Y / (2 (1 + nu)) of each
/// particle's type (all particles); Hertz time of an impact at speed vmax,
/// 2.87 (m^2 / (r Y*^2 vmax))^(1/5) with the particle's own mass and radius and
/// Y* of its type with itself (LIGGGHTS 3.8's estimate; particles of groupbit).
/// With hertz/stiffness the Hertz time takes Y* = 3 kn / 4 (the same force
/// law); with hooke/stiffness the contact time of two equal particles of a
/// type, pi sqrt(m / (2 kn)), is the `spring` time instead. The Rayleigh time
/// needs youngsModulus and poissonsRatio (optional with the stiffness models).
ContactTimes contact_times(Engine& engine, const MaterialTable& materials, const contact::ModelSpec& spec,
                           double vmax, int groupbit);

}  // namespace granary
