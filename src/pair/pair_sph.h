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

#include "neighbor/neighbor.h"
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
  double h(int t) const { return mix(t, t).h; }
  /// f(i, j, r2, h) for each pair of the neighbour list (i owned) closer than
  /// the kernel's support 2h, h the pair's smoothing length.
  template <class F>
  void for_each_pair(const Particles& p, const Neighbor& list, F&& f) const {
    for (int i = 0; i < p.nlocal; ++i) {
      const Mix* row = &mix_[static_cast<std::size_t>(p.type[i]) * ntypes1_];
      for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
        const int j = list.neigh[k];
        const double r2 = (p.x[i] - p.x[j]).squaredNorm();
        const double h = row[p.type[j]].h;
        if (r2 < 4.0 * h * h) f(i, j, r2, h);
      }
    }
  }
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
  // per type pair (index ti * (ntypes + 1) + tj, types 1-based), set at init:
  // the means of the two types' values, and the kernel at the initial spacing
  struct Mix {
    double h = 0.0, c = 0.0, alpha = 0.0, beta = 0.0, w_dp = 0.0;
  };
  const Mix& mix(int ti, int tj) const { return mix_[static_cast<std::size_t>(ti) * ntypes1_ + tj]; }
  std::vector<Mix> mix_;
  std::size_t ntypes1_ = 0;
  double eta2_ = 0.0, epsilon_ = 0.0;
  std::vector<double> p_rho2_, tension_;  // per particle, filled by compute()
  int rho_ = -1, p_ = -1;
};

}  // namespace granary
