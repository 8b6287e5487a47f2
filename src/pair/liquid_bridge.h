// Liquid bridges between spheres: the cohesion models "easo/capillary/viscous"
// and "washino/capillary/viscous" of pair_style gran (LIGGGHTS 3.8 names).
//
// Each sphere carries a surface liquid content c (fix property/atom
// surfaceLiquidContent, in % of the solid volume V = 4/3 pi r^3; the initial
// value is the property/global surfaceLiquidContentInitial). A bridge of
// volume Vb between spheres i and j pulls them together with a capillary force
// and resists their relative motion with a viscous one:
//
//   easo:    forms when the spheres touch; Vb = c_i V_i (1 - cos a_i)/2 + c_j V_j (1 - cos a_j)/2,
//            the liquid on the cap of each sphere inside the cone from its centre
//            tangent to the other (sin a_i = r_j / (r_i + r_j));
//            F_cap = pi gamma sqrt(r_i r_j) (exp(A s / R2 + B) + C) (Soulie et al. 2006)
//            with Vs = Vb / R2^3, R2 the larger radius, s the gap (0 while they overlap),
//            A = -1.1 Vs^-0.53, B = (-0.148 ln Vs - 0.96) theta^2 - 0.0082 ln Vs + 0.48,
//            C = 0.0018 ln Vs + 0.078;
//            Vb follows the contents the spheres carry at each step; at rupture
//            the bridge liquid goes back to both spheres in proportion to their
//            solid volumes: c_i -> c_i + (Vb V_i/(V_i + V_j) - c_i V_i (1 - cos a_i)/2)/V_i.
//   washino: stateless: a bridge wherever the gap is below the rupture distance;
//            Vb = 0.05 (c_i V_i + c_j V_j) (lbVolumeFraction with modifyLbVolume on);
//            F_cap = 2 pi R* gamma (cos theta / (1 + s / (2 d)) + sin(al) sin(al + theta))
//            (Rabinovich et al. 2005), p = -1 + sqrt(1 + 2 Vb / (pi R* s^2)), d = s p / 2,
//            al = sqrt(s p / R*); while they overlap by delta
//            2 pi R* gamma cos theta (1 + delta / sqrt(2 Vb / (pi R*))); no transfer.
//   both:    rupture when s > min((1 + theta/2) Vb^(1/3), (maxSeparationDistanceRatio - 1)(r_i + r_j)) (Lian
//   et al. 1993);
//            theta = theta_i theta_j / 2 (contactAngle per type, degrees, in radians);
//            viscous (Nase et al. 2001): F_n = 6 pi mu R*^2 v_n / s_v, F_t = 6 pi mu R* v_t
//            (8/15 ln(R*/s_v) + 0.9588), s_v = max(s, minSeparationDistanceRatio R*),
//            v_n, v_t the relative velocity at the contact point (spins included).
// The volume is the content number times the solid volume, without the 1/100
// of a percentage, and the contact angle is the product of the types' angles:
// what LIGGGHTS 3.8 computes (measured against it, to 1e-8 of the force; its
// manual gives the mean angle and 0.05 (V_i + V_j) for easo). The formulas,
// measurements and choices: doc/contact_models.md (Liquid bridges).
//
// The easo bridges are contact history kept with the particles: a per-particle
// field "liquidBridge" lists each sphere's bridge partners (ids); it migrates,
// goes to restart files and is not advanced by the force pass of a run's
// setup. A bridge whose partner is gone (deleted, lost) ends without transfer.
// Transfers of one pass are applied after it, so every rank sees the same
// contents during the pass. easo needs newton off (each rank keeps the bridges
// of its own spheres).
#pragma once

#include <string>
#include <vector>

#include "contact/contact_model.h"
#include "core/vec3.h"

namespace granary {

class Engine;
class Neighbor;
class Particles;

class LiquidBridge {
 public:
  /// Bridges per sphere: the field holds their count, then the partners' ids.
  static constexpr int kSlots = 32, kStride = 1 + kSlots;

  LiquidBridge(Engine& engine, contact::CohesionModel model, bool modify_lb_volume, std::string user);
  /// Before a run: read the property/global values, define the per-particle
  /// fields (fix property/atom surfaceLiquidContent; the bridge list for easo)
  /// and set the neighbour range.
  void init();
  /// Add the bridge forces and torques of every listed pair.
  void compute();
  /// Largest centre distance of a bridge per sum of radii (the neighbour range factor).
  double range_factor() const { return max_sep_; }

  /// Bridge volume [content x m^3] of two spheres with contents ci, cj.
  static double easo_volume(double ri, double rj, double ci, double cj);
  /// Capillary force magnitude [N] (> 0: attraction) at gap s (<= 0 while they overlap).
  double capillary(double ri, double rj, double s, double vb, double theta) const;

 private:
  int find(int i, double partner) const;
  void add(int i, double partner);
  void remove(int i, int slot);

  Engine& engine_;
  contact::CohesionModel model_;
  bool modify_lb_volume_;
  std::string user_;
  double min_sep_ = 1.01, max_sep_ = 1.1, gamma_ = 0.0, mu_ = 0.0, lb_fraction_ = 0.05, c0_ = 0.0;
  std::vector<double> angle_;  // contact angle per type [rad] (1-based)
  int content_ = -1, bridges_ = -1;
  std::vector<double> dcontent_;     // transfers of this pass, per owned sphere
  std::vector<unsigned char> seen_;  // per owned sphere and slot: met in this pass
};

}  // namespace granary
