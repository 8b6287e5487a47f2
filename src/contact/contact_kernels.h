// The contact formulas, each sub-model written once.
//
// Every formula is templated on two things:
//  - the number type S (contact/lane.h): a double for one contact, or a lane of
//    two or four doubles for two or four contacts at once. Branches are selections (a ternary
//    for a double), so the same text gives the same IEEE operations per lane;
//  - the sub-model slots K: which normal, tangential, rolling and cohesion
//    sub-model and whether limitForce is on. Kernel<N, T, R, Limit, C> fixes
//    them at compile time (the comparisons fold away); RuntimeKernel reads them
//    from the ModelSpec at run time. The formula text is the same for both.
//
// Only the hot combinations are compiled as Kernel types: Hertz with
// tangential history, rolling none or cdt, limitForce off or on, no cohesion
// (the model of nearly every LIGGGHTS script: 4 kernels). Every other
// combination runs through RuntimeKernel: its slot tests are branches on the
// run-time spec, uniform over a run and so predicted, on the same formula text.
// dispatch_model() picks the kernel type once per loop. doc/architecture.md
// says why.
//
// Two stages per contact, so that a pair loop can run the first over many
// contacts before the second (the first is a chain of square roots and
// divisions that does not depend on the history; across contacts the chains
// are independent and the processor overlaps them):
//   prepare()   -> Prepared<S>: coefficients, lever arms, |omega_i - omega_j|
//   interact()  -> Result<S>:   forces, torques, updated history
// evaluate() runs both for one contact given as a ContactState (walls, tests).
//
// Formulas and sign conventions: doc/contact_models.md.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <type_traits>

#include "contact/contact_model.h"
#include "contact/lane.h"

namespace granary::contact {

constexpr double kSqrtFiveSixths = 0.91287092917527685576;  // sqrt(5/6)
/// Relative rolling spins below this fraction of |omega_i| + |omega_j| count as
/// zero in the cdt model (round-off of equal spins, never real rolling).
constexpr double kRollingSpinTolerance = 1e-10;
/// Most history doubles any model needs (mindlin_deresiewicz 3 + 3, rolling spring 3,
/// hooke/hysteresis 1).
constexpr int kMaxHistory = 10;

/// Sub-model slots fixed at compile time. Every query takes the spec so that
/// the formula text is the same as for RuntimeKernel; here it is ignored.
template <NormalModel N, TangentialModel T, RollingModel R, bool Limit, CohesionModel C = CohesionModel::None>
struct Kernel {
  static constexpr bool compiled = true;
  static constexpr NormalModel normal(const ModelSpec&) { return N; }
  static constexpr TangentialModel tangential(const ModelSpec&) { return T; }
  static constexpr RollingModel rolling(const ModelSpec&) { return R; }
  static constexpr CohesionModel cohesion(const ModelSpec&) { return C; }
  static constexpr bool limit_force(const ModelSpec&) { return Limit; }
  static constexpr HistoryLayout kLayout = history_layout_of(N, T, R);
  static constexpr int shear_offset(const ModelSpec&) { return kLayout.shear; }
  static constexpr int slip_offset(const ModelSpec&) { return kLayout.slip; }
  static constexpr int rolling_offset(const ModelSpec&) { return kLayout.rolling; }
  static constexpr int hysteresis_offset(const ModelSpec&) { return kLayout.hysteresis; }
  static constexpr int history_size(const ModelSpec&) { return kLayout.size; }
};

/// Sub-model slots read from the spec at run time.
struct RuntimeKernel {
  static constexpr bool compiled = false;
  static NormalModel normal(const ModelSpec& s) { return s.normal; }
  static TangentialModel tangential(const ModelSpec& s) { return s.tangential; }
  static RollingModel rolling(const ModelSpec& s) { return s.rolling; }
  static CohesionModel cohesion(const ModelSpec& s) { return s.cohesion; }
  static bool limit_force(const ModelSpec& s) { return s.limit_force; }
  static int shear_offset(const ModelSpec& s) { return history_layout(s).shear; }
  static int slip_offset(const ModelSpec& s) { return history_layout(s).slip; }
  static int rolling_offset(const ModelSpec& s) { return history_layout(s).rolling; }
  static int hysteresis_offset(const ModelSpec& s) { return history_layout(s).hysteresis; }
  static int history_size(const ModelSpec& s) { return history_layout(s).size; }
};

/// PairMaterial with one value per lane.
template <class S>
struct MaterialT {
  S Y_eff, G_eff, beta, friction, rolling_friction, char_velocity, cohesion_energy_density, dissipative_time;
  S kn, kt, gamman, gammat;              ///< the stiffness models' coefficients as given
  S rolling_damping, rolling_stiffness;  ///< epsd, epsd3: eta_r and the prefactor of k_r
  S max_elastic_stiffness, adhesion_stiffness, plasticity_depth;  ///< hooke/hysteresis
};

/// f(field of m, the same field of p) for every field.
template <class S, class F>
[[gnu::always_inline]] inline void each_material_field(MaterialT<S>& m, const PairMaterial& p, F&& f) {
  f(m.Y_eff, p.Y_eff);
  f(m.G_eff, p.G_eff);
  f(m.beta, p.beta);
  f(m.friction, p.friction);
  f(m.rolling_friction, p.rolling_friction);
  f(m.char_velocity, p.char_velocity);
  f(m.cohesion_energy_density, p.cohesion_energy_density);
  f(m.dissipative_time, p.dissipative_time);
  f(m.rolling_damping, p.rolling_damping);
  f(m.rolling_stiffness, p.rolling_stiffness);
  f(m.max_elastic_stiffness, p.max_elastic_stiffness);
  f(m.adhesion_stiffness, p.adhesion_stiffness);
  f(m.plasticity_depth, p.plasticity_depth);
  f(m.kn, p.kn);
  f(m.kt, p.kt);
  f(m.gamman, p.gamman);
  f(m.gammat, p.gammat);
}

/// Lane l of m from the pair material p.
template <class S>
[[gnu::always_inline]] inline void set_material(MaterialT<S>& m, int l, const PairMaterial& p) {
  each_material_field(
      m, p, [l](S & a, double v) __attribute__((always_inline)) { lane::set(a, l, v); });
}

/// The lanes of m from their pair materials p[l]: when all lanes have the
/// same (one type pair, the usual case), one broadcast per field instead of a
/// value per lane.
template <class S>
[[gnu::always_inline]] inline void set_materials(MaterialT<S>& m,
                                                 const PairMaterial* const (&p)[lane::width<S>()]) {
  bool one = true;
  for (int l = 1; l < lane::width<S>(); ++l)
    one &= p[l] == p[0];
  if (one)
    each_material_field(
        m, *p[0], [](S & a, double v) __attribute__((always_inline)) { a = lane::splat<S>(v); });
  else
    for (int l = 0; l < lane::width<S>(); ++l)
      set_material(m, l, *p[l]);
}

/// The geometry of W contacts: what prepare() reads.
template <class S>
struct GeometryT {
  lane::V3<S> n;   ///< unit normal from j to i
  S overlap;       ///< r_i + r_j - |x_i - x_j| (> 0 in contact)
  S r_i, r_j;      ///< radii; r_j = 0: a wall
  S r_eff, m_eff;  ///< R*, m* (a wall: r_i, m_i)
  S i_roll;        ///< epsd, epsd3 only: the rolling inertia I_r (rolling_inertia())
  lane::V3<S> omega_i, omega_j;
};

/// What prepare() hands to interact(): everything the second stage reads
/// apart from the history and the relative velocity. A pair
/// loop keeps these for a block of contacts, so only what interact() needs is
/// here (the geometry and material of the first stage are gone by then).
template <class S>
struct PreparedT {
  lane::V3<S> n;  ///< unit normal from j to i
  S overlap, r_eff;
  S kn, kt, gamma_n, gamma_t;  ///< stiffness and damping of the normal sub-model
  S cr_i, cr_j;                ///< lever arms r - overlap/2 (a wall: 0)
  S friction, rolling_friction;
  lane::V3<S> omega_i, omega_j;  ///< spins of i and of the partner
  S spin;                        ///< cdt: |omega_i - omega_j|
  S f_coh;                       ///< sjkr, sjkr2: the cohesive pull (>= 0); unset without cohesion
  S k_roll, c_roll;              ///< epsd, epsd3: rolling stiffness k_r and dashpot C_r; unset otherwise
  S k2_max, k_c, d_star;         ///< hooke/hysteresis: k2max, kc and delta_max*; unset otherwise
};

/// The scalar history of a contact: the loading state of mindlin_deresiewicz
/// (history slot `slip`) and the plastic state of hooke/hysteresis (slot
/// `hysteresis`).
template <class S>
struct SlipT {
  S turn;     ///< tangential force at the last reversal, signed along the stored force [N]
  S t_max;    ///< the largest force reached on the virgin curve [N]
  S kt_prev;  ///< kt of the last step (0 at first touch) [N/m]
  S d_max;    ///< hooke/hysteresis: delta_max, which sets k2 and the unloading line [m]
};

/// Lane l of a slip state from its three history doubles, and back.
template <class S>
[[gnu::always_inline]] inline void load_slip(SlipT<S>& a, int l, const double* h) {
  lane::set(a.turn, l, h[0]);
  lane::set(a.t_max, l, h[1]);
  lane::set(a.kt_prev, l, h[2]);
}
template <class S>
[[gnu::always_inline]] inline void store_slip(const SlipT<S>& a, int l, double* h) {
  h[0] = lane::get(a.turn, l);
  h[1] = lane::get(a.t_max, l);
  h[2] = lane::get(a.kt_prev, l);
}

/// Forces and torques of W contacts.
template <class S>
struct ResultT {
  lane::V3<S> force;     ///< on i (j receives -force)
  lane::V3<S> torque_i;  ///< on i about its centre
  lane::V3<S> torque_j;  ///< on j about its centre
  S fn;                  ///< signed normal force (after limitForce, minus cohesion)
  lane::V3<S> ft;        ///< tangential part of force
};

/// Cohesion sjkr: magnitude of the attractive normal force (>= 0), F = k A with
/// A the area of the contact circle: for two spheres the circle in which the
/// two sphere surfaces intersect,
///   a^2 = delta (d + r_i - r_j)(d - r_i + r_j)(d + r_i + r_j) / (4 d^2),
///   d = r_i + r_j - delta,
/// for a wall (r_j = 0) the circle where the plane cuts the sphere,
///   a^2 = 2 r_i delta - delta^2;
/// A = pi a^2.
template <class S>
[[gnu::always_inline]] inline S sjkr_force(const GeometryT<S>& g, const MaterialT<S>& m) {
  using lane::select;
  const S d = g.r_i + g.r_j - g.overlap;
  const S a2_pair =
      g.overlap * (d + g.r_i - g.r_j) * (d - g.r_i + g.r_j) * (d + g.r_i + g.r_j) / (4.0 * d * d);
  const S a2_wall = g.overlap * (2.0 * g.r_i - g.overlap);
  const S a2 = select(g.r_j > 0.0, a2_pair, a2_wall);
  return m.cohesion_energy_density * M_PI * select(a2 < 0.0, lane::splat<S>(0.0), a2);
}

/// First stage: the normal sub-model's coefficients, the lever arms, the
/// relative spin and the cohesive pull. None of it depends on the history.
template <class K, class S>
[[gnu::always_inline]] inline void prepare(const ModelSpec& spec, const GeometryT<S>& g,
                                           const MaterialT<S>& m, PreparedT<S>& q) {
  using lane::select;
  using lane::sqrt;
  if (K::normal(spec) == NormalModel::Hertz) {
    // Hertz with the damping of Tsuji et al. in the form used by LIGGGHTS.
    const S sqrtval = sqrt(S(g.r_eff * g.overlap));
    const S sn = 2.0 * m.Y_eff * sqrtval;
    const S st = 8.0 * m.G_eff * sqrtval;
    q.kn = (4.0 / 3.0) * m.Y_eff * sqrtval;
    q.kt = st;
    if (spec.damping == DampingModel::Viscoelastic) {
      // Brilliantov et al. (1996): the dissipative force is A d/dt of the
      // elastic force's overlap dependence, -A (3/2) kn vn = -A S_n vn, with
      // S_n = 2 Y* sqrt(R* delta) the tangent stiffness; the tangential
      // dashpot uses the same relaxation time on the tangential stiffness.
      q.gamma_n = m.dissipative_time * sn;
      q.gamma_t = m.dissipative_time * st;
    } else {
      const S root_n = sqrt(S(sn * g.m_eff));
      const S root_t = sqrt(S(st * g.m_eff));
      q.gamma_n = -2.0 * kSqrtFiveSixths * m.beta * root_n;
      q.gamma_t = -2.0 * kSqrtFiveSixths * m.beta * root_t;
    }
  } else if (K::normal(spec) == NormalModel::HookeStiffness) {
    // The spring and dashpot as given; the dashpots scale with the effective
    // mass unless absolute_damping is on.
    q.kn = m.kn;
    q.kt = m.kt;
    q.gamma_n = spec.absolute_damping ? m.gamman : S(m.gamman * g.m_eff);
    q.gamma_t = spec.absolute_damping ? m.gammat : S(m.gammat * g.m_eff);
  } else if (K::normal(spec) == NormalModel::HertzStiffness) {
    // The given coefficients times sqrt(delta R*) (the dashpots also times m*).
    const S root = sqrt(S(g.overlap * g.r_eff));
    q.kn = m.kn * root;
    q.kt = m.kt * root;
    q.gamma_n = m.gamman * g.m_eff * root;
    q.gamma_t = m.gammat * g.m_eff * root;
  } else {
    // Linear spring whose stiffness gives the Hertz maximum overlap at the
    // characteristic impact velocity V:
    //   kn = 16/15 sqrt(R*) Y* (15 m* V^2 / (16 sqrt(R*) Y*))^(1/5).
    const S sqrt_r = sqrt(g.r_eff);
    const S v = m.char_velocity;
    q.kn = (16.0 / 15.0) * sqrt_r * m.Y_eff *
           lane::pow(S(15.0 * g.m_eff * v * v / (16.0 * sqrt_r * m.Y_eff)), 0.2);
    q.kt = spec.kt_to_kn_user ? S((2.0 / 7.0) * q.kn) : q.kn;
    // sqrt(4 m* kn / (1 + (pi/ln e)^2)) written so that e = 1 gives exactly 0.
    q.gamma_n = -2.0 * m.beta * sqrt(S(g.m_eff * q.kn));
    q.gamma_t = q.gamma_n;
  }
  if (K::normal(spec) == NormalModel::HookeHysteresis) {
    // Luding (2008) on the stiffness k1 = kn of model hooke: k2 grows with
    // delta_max up to k2max, reached at delta_max* = k2max / (k2max - k1) phi_f 2 R*
    q.k2_max = m.max_elastic_stiffness * q.kn;
    q.k_c = m.adhesion_stiffness * q.kn;
    q.d_star = m.max_elastic_stiffness / (m.max_elastic_stiffness - 1.0) * m.plasticity_depth * 2.0 * g.r_eff;
  } else if constexpr (!K::compiled) {
    q.k2_max = q.k_c = q.d_star = lane::splat<S>(0.0);  // read by no one
  }
  if (!spec.tangential_damping) q.gamma_t = lane::splat<S>(0.0);
  q.n = g.n;
  q.overlap = g.overlap;
  q.r_eff = g.r_eff;
  q.friction = m.friction;
  q.rolling_friction = m.rolling_friction;
  q.omega_i = g.omega_i;
  q.omega_j = g.omega_j;
  if (K::cohesion(spec) == CohesionModel::Sjkr)
    q.f_coh = sjkr_force(g, m);
  else if (K::cohesion(spec) == CohesionModel::Sjkr2)
    // sjkr2: A = 2 pi delta 2R* between spheres; against a wall 2 pi delta r
    // (LIGGGHTS 3.8, measured: not 2 pi delta 2r)
    q.f_coh =
        m.cohesion_energy_density * (2.0 * M_PI) * g.overlap * select(g.r_j > 0.0, S(2.0 * g.r_eff), g.r_eff);
  else if constexpr (!K::compiled)
    q.f_coh = lane::splat<S>(0.0);  // read by no one; set so that the value is defined
  // The contact point lies in the middle of the overlap region, at distance
  // r - delta/2 from each centre (a wall has no lever arm).
  q.cr_i = g.r_i - 0.5 * g.overlap;
  q.cr_j = select(g.r_j > 0.0, S(g.r_j - 0.5 * g.overlap), lane::splat<S>(0.0));
  if (K::rolling(spec) == RollingModel::Cdt) {
    const lane::V3<S> w = g.omega_i - g.omega_j;
    q.spin = sqrt(dot(w, w));  // Eigen's norm: sqrt((x^2 + y^2) + z^2)
  } else {
    q.spin = lane::splat<S>(0.0);
  }
  if (rolling_dashpot(K::rolling(spec))) {
    // epsd (Ai et al. 2011): k_r = 2.25 kn mu_r^2 R*^2 (epsd3: rollingStiffness
    // in place of 2.25), C_r = eta_r 2 sqrt(I_r k_r)
    q.k_roll = m.rolling_stiffness * q.kn * m.rolling_friction * m.rolling_friction * g.r_eff * g.r_eff;
    q.c_roll = m.rolling_damping * 2.0 * sqrt(S(g.i_roll * q.k_roll));
  } else if constexpr (!K::compiled) {
    q.k_roll = q.c_roll = lane::splat<S>(0.0);  // read by no one; set so that the values are defined
  }
}

/// Second stage: forces and torques of W contacts from the first stage's `q`
/// (the spins included), the relative velocity of the centres `v_rel`
/// (v_i - v_j; a wall: v_i minus the wall's velocity) and the timestep `dt`. `shear` (tangential history,
/// mindlin_deresiewicz), `slip` (mindlin_deresiewicz) and `roll` (epsd2 spring
/// torque) are the contacts' history, updated in place; a slot the model does
/// not use is left alone. A lane whose overlap is not positive gets a zero
/// result and a zero history.
template <class K, class S>
[[gnu::always_inline]] inline void interact(const ModelSpec& spec, const PreparedT<S>& q,
                                            const lane::V3<S>& v_rel, HistoryDt hdt, lane::V3<S>& shear,
                                            SlipT<S>& slip, lane::V3<S>& roll, ResultT<S>& out) {
  using lane::select;
  using lane::splat;
  using V = lane::V3<S>;
  const double dt = hdt.tangential;
  const V n = q.n;
  const V& omega_i = q.omega_i;
  // Normal force: spring + dashpot; vn < 0 while approaching, so the dashpot
  // pushes the bodies apart on approach and pulls on separation.
  const S vn = dot(v_rel, n);
  S fn_elastic = q.kn * q.overlap;
  S d_max_new = slip.d_max;
  if (K::normal(spec) == NormalModel::HookeHysteresis) {
    // Luding (2008): loading on k1 delta; unloading and reloading on
    // k2 (delta - delta_0), delta_0 = (1 - k1/k2) delta_max; no more pull than
    // -kc delta, where delta_max follows so that the k2 line passes through
    // (delta, -kc delta) and reloading starts from there.
    const S k1 = q.kn, d = q.overlap;
    const S dk = q.k2_max - k1;
    const S d_max = select(slip.d_max > d, slip.d_max, d);
    const S k2 = select(d_max >= q.d_star, q.k2_max, S(k1 + dk * (d_max / q.d_star)));
    const S f2 = k2 * (d - (1.0 - k1 / k2) * d_max);
    const S f1 = k1 * d, fc = -q.k_c * d;
    fn_elastic = select(f2 >= f1, f1, select(f2 > fc, f2, fc));
    // on the adhesive branch: x = delta_max / delta_max* solves
    // dk delta* x^2 - dk delta x - (k1 + kc) delta = 0 (k2 below k2max),
    // else delta_max = delta (k2max + kc) / (k2max - k1)
    const S x = (dk * d + lane::sqrt(S(dk * dk * d * d + 4.0 * dk * q.d_star * (k1 + q.k_c) * d))) /
                (2.0 * dk * q.d_star);
    const S d_adh = select(x >= 1.0, S(d * (q.k2_max + q.k_c) / dk), S(x * q.d_star));
    d_max_new = select(f2 > fc, d_max, d_adh);
  }
  S fn = fn_elastic - q.gamma_n * vn;
  if (K::limit_force(spec)) fn = select(fn < 0.0, splat<S>(0.0), fn);
  // Cohesion pulls the bodies together after limitForce (which forbids only
  // the attraction of the dashpot). By default the Coulomb and rolling limits
  // below see the contact force without it (LIGGGHTS "tangential_reduce off");
  // with "tangential_reduce on" they see |fn - F_coh| (LIGGGHTS 3.8, measured).
  S fn_total = fn;
  if (K::cohesion(spec) == CohesionModel::Sjkr || K::cohesion(spec) == CohesionModel::Sjkr2) {
    fn_total = fn - q.f_coh;
    if (spec.tangential_reduce) fn = fn_total;
  }
  V force = fn_total * n;
  V torque_i = lane::zero3<S>(), torque_j = lane::zero3<S>(), ft = lane::zero3<S>();
  V s_new = shear;
  SlipT<S> slip_new = slip;

  const TangentialModel tm = K::tangential(spec);
  if (tm != TangentialModel::None) {
    // Tangential relative velocity of the contact points: the tangential part
    // of the centre velocities minus the surface velocity from the spins,
    // (v_rel - vn n) - w x n. w x n already lies in the tangent plane, so no
    // second projection; this order of evaluation is LIGGGHTS', and it decides
    // the round-off that CDT rolling friction amplifies in symmetric packings.
    const V w = q.cr_i * omega_i + q.cr_j * q.omega_j;
    const V vt = (v_rel - vn * n) - cross(w, n);
    const S ft_max = q.friction * lane::abs(fn);
    if (tm == TangentialModel::History) {
      // Integrate the tangential displacement, then keep it in the current
      // tangent plane (the contact normal may have rotated since the last step).
      V s = shear + dt * vt;
      s = s - dot(s, n) * n;
      const S minus_kt = -q.kt;
      ft = minus_kt * s;
      const S ft_spring = q.kt * lane::sqrt(dot(s, s));
      const auto slip = ft_spring > ft_max;
      if (lane::any(slip)) {
        // Slip: the spring force is held at the Coulomb limit and the stored
        // displacement shrunk to match; no damping in a slipping step. (Four
        // divisions per lane, only when a lane slips: in a resting bed rarely.)
        const V ft_slip = (ft_max / ft_spring) * ft;
        const V s_slip = {ft_slip.x / minus_kt, ft_slip.y / minus_kt, ft_slip.z / minus_kt};
        ft = select(slip, ft_slip, V(ft - q.gamma_t * vt));
        s = select(slip, s_slip, s);
      } else {
        ft = ft - q.gamma_t * vt;  // stick: spring + dashpot
      }
      s_new = s;
    } else if (tm == TangentialModel::MindlinDeresiewicz) {
      // Partial slip (Mindlin & Deresiewicz 1953) with Masing's rules, in
      // incremental form along the tangential force F: the force grows by
      // -theta kt dt vt, with kt the stiffness of the no-slip contact and
      //   theta = (1 - T/(mu Fn))^(1/3)            on the virgin curve,
      //   theta = (1 - |T - T*|/(2 mu Fn))^(1/3)   after a reversal at T*,
      // T = |F| and T* signed along F. The virgin curve is Mindlin's first
      // loading; a reversal starts a branch of twice the virgin curve (Masing),
      // which joins the virgin curve again where the force passes the largest
      // force reached on it (T_max). So the contact softens to 0 at the
      // Coulomb limit, and a load cycle below the limit traces a hysteresis
      // loop: the micro-slip in the rim of the contact circle. Only the last
      // reversal is remembered (nested loops are not). When the contact grows
      // or shrinks, F, T* and T_max scale with kt (with the contact radius):
      // far from the limit (theta = 1) the force is tangential history's,
      // -kt times the accumulated displacement.
      V F = shear - dot(shear, n) * n;  // into the current tangent plane
      const S scale =
          select(slip.kt_prev > 0.0, S(q.kt / select(slip.kt_prev > 0.0, slip.kt_prev, splat<S>(1.0))),
                 splat<S>(1.0));
      F = scale * F;
      S turn = scale * slip.turn;
      S t_max = scale * slip.t_max;
      const V dd = dt * vt;
      const S T = lane::sqrt(dot(F, F));
      const auto grows = -dot(dd, F) >= 0.0;  // a fresh contact (F = 0) grows
      // a reversal of the loading: the force there is the new T*
      turn = select(grows, select(turn > T, T, turn), select(turn < T, T, turn));
      const auto virgin = lane::mask_and(grows, T >= t_max);
      const S limit = select(ft_max > 0.0, ft_max, splat<S>(1.0));
      S x = select(virgin, S(T / limit), S(lane::abs(S(T - turn)) / (2.0 * limit)));
      x = select(ft_max > 0.0, x, splat<S>(1.0));
      x = select(x > 1.0, splat<S>(1.0), x);
      const S theta = lane::cbrt(S(1.0 - x));
      V F_new = F - (theta * q.kt) * dd;
      // the force passed through zero: T* is measured along the other way now
      turn = select(dot(F_new, F) < 0.0, S(-turn), turn);
      // Coulomb: a slipping contact keeps the limit force, no damping
      const S mag = lane::sqrt(dot(F_new, F_new));
      const auto slipping = mag > ft_max;
      F_new = select(slipping, V((ft_max / select(mag > 0.0, mag, splat<S>(1.0))) * F_new), F_new);
      const S mag_new = select(slipping, ft_max, mag);
      ft = select(slipping, F_new, V(F_new - q.gamma_t * vt));
      s_new = F_new;
      slip_new.turn = turn;
      // full slip wipes the memory of the loading: the contact is on the
      // virgin curve at the limit, where the next reversal starts its branch
      slip_new.t_max =
          select(slipping, ft_max, select(virgin, select(mag_new > t_max, mag_new, t_max), t_max));
      slip_new.kt_prev = q.kt;
    } else {
      // no_history: pure viscous friction, limited by Coulomb:
      // -min(gamma_t |vt|, mu |Fn|) vt/|vt|
      const S vt_mag = lane::sqrt(dot(vt, vt));
      const S viscous = q.gamma_t * vt_mag;
      const S ft_mag = select(ft_max < viscous, ft_max, viscous);
      ft = select(vt_mag > 0.0, V((-ft_mag / vt_mag) * vt), lane::zero3<S>());
    }
    force = force + ft;
    // ft acts on i at x_i - cr_i n and -ft on j at x_j + cr_j n.
    const V n_x_ft = cross(n, ft);
    torque_i = -q.cr_i * n_x_ft;
    torque_j = -q.cr_j * n_x_ft;
  }

  const RollingModel rm = K::rolling(spec);
  V roll_new = roll;
  if (rm != RollingModel::None) {
    // Relative spin without its twisting (normal) part.
    V wr = omega_i - q.omega_j;
    wr = wr - dot(wr, n) * n;
    V mr;
    if (rm == RollingModel::Cdt) {
      // Constant directional torque mu_r (kn delta) R*, opposing the rolling
      // (tangential) part of the relative spin and scaled by its share of the
      // whole relative spin |w_r|, twist included, as LIGGGHTS does: a contact
      // that also twists gets a smaller rolling torque.
      // A relative spin at the round-off level of the spins themselves (two
      // bodies turning together) gets no torque: its direction is noise.
      // (|a| + |b|)^2 <= 2 (a^2 + b^2): a relative spin clearly above the
      // tolerance (the usual case) is recognised without the two square roots;
      // the factor 4 instead of 2 leaves room for the rounding of the bound.
      const S w_full = q.spin;
      const S w2 = w_full * w_full;
      const S s2 = dot(omega_i, omega_i) + dot(q.omega_j, q.omega_j);
      constexpr double tol = kRollingSpinTolerance;
      const auto clearly = w2 > 4.0 * tol * tol * s2;
      lane::Mask<S> none{};
      if (!lane::all(clearly)) {  // rare: spins equal to round-off
        const S bound = tol * (lane::sqrt(dot(omega_i, omega_i)) + lane::sqrt(dot(q.omega_j, q.omega_j)));
        none = lane::mask_andnot(clearly, w_full <= bound);
      }
      const S scale = -q.rolling_friction * fn_elastic * q.r_eff / w_full;
      mr = select(none, lane::zero3<S>(), V(scale * wr));
    } else {
      // epsd2, epsd, epsd3: an elastic-plastic spring, incremental spring
      // torque with k_r = kt R*^2 (epsd2) or k_r of prepare() (epsd, epsd3),
      // capped at full mobilisation mu_r R* |Fn|; epsd and epsd3 add the
      // dashpot -C_r w_r while the spring is below the cap.
      const S kr = rm == RollingModel::Epsd2 ? S(q.kt * q.r_eff * q.r_eff) : q.k_roll;
      V t = roll - (kr * hdt.rolling) * wr;
      const S t_max = q.rolling_friction * q.r_eff * lane::abs(fn);
      const S t_mag = lane::sqrt(dot(t, t));
      const auto capped = t_mag > t_max;
      t = select(capped, V((t_max / t_mag) * t), t);
      roll_new = t;
      mr = t;
      if (rolling_dashpot(rm)) mr = mr + select(capped, lane::zero3<S>(), V(-q.c_roll * wr));
    }
    torque_i = torque_i + mr;
    torque_j = torque_j - mr;
  }

  const auto touching = q.overlap > 0.0;
  const V zero = lane::zero3<S>();
  out.force = select(touching, force, zero);
  out.torque_i = select(touching, torque_i, zero);
  out.torque_j = select(touching, torque_j, zero);
  out.ft = select(touching, ft, zero);
  out.fn = select(touching, fn_total, splat<S>(0.0));
  if (tm == TangentialModel::History || tm == TangentialModel::MindlinDeresiewicz)
    shear = select(touching, s_new, zero);
  if (tm == TangentialModel::MindlinDeresiewicz) {
    slip.turn = select(touching, slip_new.turn, splat<S>(0.0));
    slip.t_max = select(touching, slip_new.t_max, splat<S>(0.0));
    slip.kt_prev = select(touching, slip_new.kt_prev, splat<S>(0.0));
  }
  if (rolling_spring(rm)) roll = select(touching, roll_new, zero);
  if (K::normal(spec) == NormalModel::HookeHysteresis)
    slip.d_max = select(touching, d_max_new, splat<S>(0.0));
}

/// One contact given as a ContactState: the same formulas on one lane. Same
/// contract as contact::evaluate().
template <class K>
[[gnu::always_inline]] inline void evaluate_with(const ModelSpec& spec, const ContactState& c,
                                                 const PairMaterial& m, double* history, ContactResult& out) {
  const int nh = K::history_size(spec);
  if (!(c.overlap > 0.0)) {
    out = ContactResult();
    for (int h = 0; h < nh; ++h)
      history[h] = 0.0;
    return;
  }
  using V = lane::V3<double>;
  auto v3 = [](const Vec3& a) { return V{a[0], a[1], a[2]}; };
  GeometryT<double> g;
  g.n = v3(c.n);
  g.overlap = c.overlap;
  g.r_i = c.r_i;
  g.r_j = c.r_j;
  g.r_eff = c.r_eff;
  g.m_eff = c.m_eff;
  g.i_roll = c.i_roll;
  g.omega_i = v3(c.omega_i);
  g.omega_j = v3(c.omega_j);
  MaterialT<double> mat;
  set_material(mat, 0, m);
  PreparedT<double> q;
  prepare<K>(spec, g, mat, q);
  const int so = K::shear_offset(spec), po = K::slip_offset(spec), ro = K::rolling_offset(spec);
  V shear = so >= 0 ? V{history[so], history[so + 1], history[so + 2]} : lane::zero3<double>();
  SlipT<double> slip{0.0, 0.0, 0.0, 0.0};
  if (po >= 0) load_slip(slip, 0, history + po);
  const int ho = K::hysteresis_offset(spec);
  if (ho >= 0) slip.d_max = history[ho];
  V roll = ro >= 0 ? V{history[ro], history[ro + 1], history[ro + 2]} : lane::zero3<double>();
  ResultT<double> r;
  interact<K>(spec, q, v3(c.v_rel), HistoryDt{c.dt, c.dt}, shear, slip, roll, r);
  if (so >= 0) lane::store(shear, 0, history + so);
  if (po >= 0) store_slip(slip, 0, history + po);
  if (ro >= 0) lane::store(roll, 0, history + ro);
  if (ho >= 0) history[ho] = slip.d_max;
  out.force = lane::get(r.force, 0);
  out.torque_i = lane::get(r.torque_i, 0);
  out.torque_j = lane::get(r.torque_j, 0);
  out.fn = r.fn;
  out.ft = lane::get(r.ft, 0);
}

/// True for the combinations compiled as Kernel types (see the top of this file).
inline bool hot(const ModelSpec& s) {
  return s.normal == NormalModel::Hertz && s.tangential == TangentialModel::History &&
         (s.rolling == RollingModel::None || s.rolling == RollingModel::Cdt) &&
         s.cohesion == CohesionModel::None;
}

/// Call fn(K{}) with the kernel type for the run-time spec: one of the four
/// compiled hot kernels, or RuntimeKernel; return what fn returns (the same
/// type for every kernel).
template <class Fn>
inline decltype(auto) dispatch_model(const ModelSpec& s, Fn&& fn) {
  constexpr auto H = NormalModel::Hertz;
  constexpr auto TH = TangentialModel::History;
  if (hot(s)) {
    if (s.rolling == RollingModel::Cdt) {
      if (s.limit_force) return fn(Kernel<H, TH, RollingModel::Cdt, true>{});
      return fn(Kernel<H, TH, RollingModel::Cdt, false>{});
    }
    if (s.limit_force) return fn(Kernel<H, TH, RollingModel::None, true>{});
    return fn(Kernel<H, TH, RollingModel::None, false>{});
  }
  return fn(RuntimeKernel{});
}

}  // namespace granary::contact
