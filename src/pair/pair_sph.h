// Smoothed particle hydrodynamics (atom_style sph):
//
//   pair_style sph/artVisc/tensCorr KERNEL h [artVisc [alpha beta eta]] [tensCorr [epsilon deltap]]
//
// Monaghan's (1992) momentum equation, with his artificial viscosity (1985)
// and tensile correction (2000) when asked for. Parameters not given on the
// line come from fix property/global (speedOfSound, sl, artViscAlpha,
// artViscBeta, artViscEta, tensCorrEpsilon, tensCorrDeltaP), as in LIGGGHTS.
// The SPH fixes (density, pressure, walls) use this style's kernel and
// smoothing lengths. See doc/pairs/sph_artvisc_tenscorr.md.
#pragma once

#include <string>
#include <vector>

#include "pair/pair.h"
#include "pair/sph_kernel.h"
#include "particles/particles.h"

namespace granary {

class PairSph : public Pair {
 public:
  PairSph(Engine& engine, const Args& args);
  void coeff(const Args& args) override;
  void init() override;
  void compute() override;

  sph::Kernel kernel() const { return kernel_; }
  /// Smoothing length of type t (1-based), after init.
  double h(int t) const { return h_[t]; }
  /// Smoothing length of a pair: the mean of the two types'.
  double h(int ti, int tj) const { return 0.5 * (h_[ti] + h_[tj]); }
  /// Force on owned particle i from its clone at x_i - dx (fix wall/region/sph:
  /// a particle of the same mass, density and pressure at the wall point),
  /// through the pressure and tensile-correction terms of the momentum equation.
  Vec3 clone_force(const Particles& p, int i, const Vec3& dx) const;
  /// The per-particle fields of atom_style sph (InputError without it).
  static int field(const Engine& engine, const char* name, const std::string& who);

 private:
  sph::Kernel kernel_ = sph::Kernel::CubicSpline;
  double h_arg_ = 0.0;
  bool artvisc_ = false, tenscorr_ = false;
  std::vector<double> artvisc_args_, tenscorr_args_;  // given on the pair_style line (else properties)
  bool coeff_set_ = false;
  // per type (index 1..ntypes) and scalars, read at init
  std::vector<double> h_, c_, alpha_, beta_, deltap_;
  double eta2_ = 0.0, epsilon_ = 0.0;
  int rho_ = -1, p_ = -1;
};

}  // namespace granary
