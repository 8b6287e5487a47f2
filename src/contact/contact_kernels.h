// Inline, templated contact kernels. Each sub-model slot is one small function
// templated on its model enum; evaluate_t<Normal, Tangential, Rolling, Limit,
// Cohesion> chains them for one contact with no allocation, no virtual call and
// no runtime branch on the model choice.
//
// Instantiated combinations: all of them. The current slots span
// 2 normal x 3 tangential x 3 rolling x limitForce on/off x 2 cohesion = 72
// kernels, few enough that every combination is compiled and no generic slow
// path exists. The damping choice of the Hertz model (restitution or
// viscoelastic) is a runtime branch inside normal_coefficients(): it changes
// two coefficients once per contact and would otherwise double the count.
// dispatch_model() turns a runtime ModelSpec into the matching Kernel type once,
// so a pair loop can be compiled for exactly that kernel:
//
//   dispatch_model(spec, [&](auto kernel) {
//     using K = decltype(kernel);
//     for (...) K::evaluate(spec, state, material, history, result);
//   });
//
// Formulas and sign conventions: doc/contact_models.md.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <algorithm>
#include <cmath>

#include "contact/contact_model.h"

namespace granary::contact {

namespace detail {

constexpr double kSqrtFiveSixths = 0.91287092917527685576;  // sqrt(5/6)

/// Stiffness and damping coefficients of one contact evaluation.
struct Coefficients {
  double kn;       ///< normal stiffness: elastic normal force = kn * overlap
  double kt;       ///< tangential stiffness
  double gamma_n;  ///< normal damping coefficient (>= 0)
  double gamma_t;  ///< tangential damping coefficient (>= 0)
};

/// Square roots of one contact that do not depend on its history: those of
/// the Hertz coefficients and the magnitude of the relative spin. A pair loop
/// can compute them for all contacts of a particle in a pass of its own
/// (independent iterations that the processor overlaps) before the kernels
/// run; otherwise evaluate() computes them first. Same operations either way.
struct Roots {
  double sqrt_rd = 0.0;  ///< Hertz: sqrt(R* delta)
  double root_n = 0.0;   ///< Hertz, restitution damping: sqrt(S_n m*), S_n = 2 Y* sqrt(R* delta)
  double root_t = 0.0;   ///< Hertz, restitution damping: sqrt(S_t m*), S_t = 8 G* sqrt(R* delta)
  double spin = 0.0;     ///< rolling models: |omega_i - omega_j|
};

[[gnu::always_inline]] inline double root(double x) {
  return std::sqrt(x);
}
[[gnu::always_inline]] inline Eigen::Array2d root(const Eigen::Array2d& x) {
  return x.sqrt();
}

/// The roots of Roots for one contact (S = double) or two at once (S =
/// Eigen::Array2d, one contact per lane: packed square roots, the same IEEE
/// result per lane). `w` is omega_i - omega_j (cdt only).
template <NormalModel N, RollingModel R, class S>
[[gnu::always_inline]] inline void contact_roots_lanes(const ModelSpec& spec, const S& r_eff,
                                                       const S& overlap, const S& m_eff, const S& Y_eff,
                                                       const S& G_eff, const S& wx, const S& wy, const S& wz,
                                                       S& sqrt_rd, S& root_n, S& root_t, S& spin) {
  if constexpr (N == NormalModel::Hertz) {
    const S sqrtval = root(S(r_eff * overlap));
    sqrt_rd = sqrtval;
    if (spec.damping != DampingModel::Viscoelastic) {
      const S sn = 2.0 * Y_eff * sqrtval;
      const S st = 8.0 * G_eff * sqrtval;
      root_n = root(S(sn * m_eff));
      root_t = root(S(st * m_eff));
    }
  } else {
    (void)spec, (void)r_eff, (void)overlap, (void)m_eff, (void)Y_eff, (void)G_eff, (void)sqrt_rd,
        (void)root_n, (void)root_t;
  }
  // Eigen's norm of a 3-vector: sqrt((x^2 + y^2) + z^2)
  if constexpr (R == RollingModel::Cdt) {
    spin = root(S((wx * wx + wy * wy) + wz * wz));
  } else {
    (void)wx, (void)wy, (void)wz, (void)spin;
  }
}

template <NormalModel N, RollingModel R>
[[gnu::always_inline]] inline void contact_roots(const ModelSpec& spec, const ContactState& c,
                                                 const PairMaterial& m, Roots& q) {
  const Vec3 w = c.omega_i - c.omega_j;
  contact_roots_lanes<N, R, double>(spec, c.r_eff, c.overlap, c.m_eff, m.Y_eff, m.G_eff, w[0], w[1], w[2],
                                    q.sqrt_rd, q.root_n, q.root_t, q.spin);
}

/// Normal sub-model: stiffness and damping for the current overlap.
template <NormalModel N>
[[gnu::always_inline]] inline Coefficients normal_coefficients(const ModelSpec& spec, const ContactState& c,
                                                               const PairMaterial& m, const Roots& q) {
  Coefficients k;
  if constexpr (N == NormalModel::Hertz) {
    // Hertz with the damping of Tsuji et al. in the form used by LIGGGHTS.
    const double sqrtval = q.sqrt_rd;
    const double sn = 2.0 * m.Y_eff * sqrtval;
    const double st = 8.0 * m.G_eff * sqrtval;
    k.kn = (4.0 / 3.0) * m.Y_eff * sqrtval;
    k.kt = st;
    if (spec.damping == DampingModel::Viscoelastic) {
      // Brilliantov et al. (1996): the dissipative force is A d/dt of the
      // elastic force's overlap dependence, -A (3/2) kn vn = -A S_n vn, with
      // S_n = 2 Y* sqrt(R* delta) the tangent stiffness; the tangential
      // dashpot uses the same relaxation time on the tangential stiffness.
      k.gamma_n = m.dissipative_time * sn;
      k.gamma_t = m.dissipative_time * st;
    } else {
      k.gamma_n = -2.0 * kSqrtFiveSixths * m.beta * q.root_n;
      k.gamma_t = -2.0 * kSqrtFiveSixths * m.beta * q.root_t;
    }
  } else {
    (void)q;
    // Linear spring whose stiffness gives the Hertz maximum overlap at the
    // characteristic impact velocity V:
    //   kn = 16/15 sqrt(R*) Y* (15 m* V^2 / (16 sqrt(R*) Y*))^(1/5).
    const double sqrt_r = std::sqrt(c.r_eff);
    const double v = m.char_velocity;
    k.kn =
        (16.0 / 15.0) * sqrt_r * m.Y_eff * std::pow(15.0 * c.m_eff * v * v / (16.0 * sqrt_r * m.Y_eff), 0.2);
    k.kt = spec.kt_to_kn_user ? (2.0 / 7.0) * k.kn : k.kn;
    // sqrt(4 m* kn / (1 + (pi/ln e)^2)) written so that e = 1 gives exactly 0.
    k.gamma_n = -2.0 * m.beta * std::sqrt(c.m_eff * k.kn);
    k.gamma_t = k.gamma_n;
  }
  if (!spec.tangential_damping) k.gamma_t = 0.0;
  return k;
}

/// Size of the history block of each slot (doubles).
template <TangentialModel T>
constexpr int tangential_history_size() {
  return T == TangentialModel::History ? 3 : 0;
}
template <RollingModel R>
constexpr int rolling_history_size() {
  return R == RollingModel::Epsd2 ? 3 : 0;
}

/// Tangential sub-model: force on i at the contact point. `vt` is the
/// tangential relative velocity of the contact point, `fn` the total normal
/// force, `shear` the slot's history block (only read for History).
template <TangentialModel T>
[[gnu::always_inline]] inline Vec3 tangential_force(const ContactState& c, const PairMaterial& m,
                                                    const Coefficients& k, double fn, const Vec3& vt,
                                                    double* shear) {
  const double ft_max = m.friction * std::abs(fn);
  if constexpr (T == TangentialModel::NoHistory) {
    // Pure viscous friction, limited by Coulomb: -min(gamma_t |vt|, mu |Fn|) vt/|vt|.
    const double vt_mag = vt.norm();
    if (vt_mag <= 0.0) return Vec3::Zero();
    const double ft_mag = std::min(k.gamma_t * vt_mag, ft_max);
    return (-ft_mag / vt_mag) * vt;
  } else if constexpr (T == TangentialModel::History) {
    // Integrate the tangential displacement, then keep it in the current
    // tangent plane (the contact normal may have rotated since the last step).
    Eigen::Map<Vec3> s(shear);
    s += c.dt * vt;
    s -= s.dot(c.n) * c.n;
    Vec3 ft = -k.kt * s;
    const double ft_spring = k.kt * s.norm();
    if (ft_spring > ft_max) {
      // Slip (ft_spring > 0 here): the spring force is held at the Coulomb limit
      // and the stored displacement shrunk to match; no damping in a slipping step.
      ft *= ft_max / ft_spring;
      s = ft / (-k.kt);
    } else {
      ft -= k.gamma_t * vt;  // stick: spring + dashpot
    }
    return ft;
  } else {
    (void)c, (void)m, (void)k, (void)fn, (void)vt, (void)shear, (void)ft_max;
    return Vec3::Zero();
  }
}

/// Rolling sub-model: rolling-resistance torque on i (j receives the opposite).
/// `fn` is the total normal force, `fn_elastic` = kn * overlap, `hist` the
/// slot's history block (only used by epsd2).
/// Relative rolling spins below this fraction of |omega_i| + |omega_j| count as
/// zero in the cdt model (round-off of equal spins, never real rolling).
constexpr double kRollingSpinTolerance = 1e-10;

template <RollingModel R>
[[gnu::always_inline]] inline Vec3 rolling_torque(const ContactState& c, const PairMaterial& m,
                                                  const Coefficients& k, const Roots& q, double fn,
                                                  double fn_elastic, double* hist) {
  if constexpr (R == RollingModel::None) {
    (void)c, (void)m, (void)k, (void)q, (void)fn, (void)fn_elastic, (void)hist;
    return Vec3::Zero();
  } else {
    // Relative spin without its twisting (normal) part.
    Vec3 w = c.omega_i - c.omega_j;
    const double w_full = q.spin;  // |omega_i - omega_j| (cdt only)
    w -= w.dot(c.n) * c.n;
    if constexpr (R == RollingModel::Cdt) {
      // Constant directional torque mu_r (kn delta) R*, opposing the rolling
      // (tangential) part of the relative spin and scaled by its share of the
      // whole relative spin |w_r|, twist included, as LIGGGHTS does: a contact
      // that also twists gets a smaller rolling torque.
      (void)hist, (void)fn;
      // A relative spin at the round-off level of the spins themselves (two
      // bodies turning together) gets no torque: its direction is noise.
      // (|a| + |b|)^2 <= 2 (a^2 + b^2): a relative spin clearly above the
      // tolerance (the usual case) is recognised without the two square roots;
      // the factor 4 instead of 2 leaves room for the rounding of the bound.
      const double w2 = w_full * w_full;
      const double s2 = c.omega_i.squaredNorm() + c.omega_j.squaredNorm();
      if (!(w2 > 4.0 * kRollingSpinTolerance * kRollingSpinTolerance * s2) &&
          w_full <= kRollingSpinTolerance * (c.omega_i.norm() + c.omega_j.norm()))
        return Vec3::Zero();
      return (-m.rolling_friction * fn_elastic * c.r_eff / w_full) * w;
    } else {
      // Elastic-plastic spring: incremental spring torque with k_r = kt R*^2,
      // capped at full mobilisation mu_r R* |Fn|.
      (void)fn_elastic, (void)w_full;
      Eigen::Map<Vec3> torque(hist);
      const double kr = k.kt * c.r_eff * c.r_eff;
      torque -= (kr * c.dt) * w;
      const double t_max = m.rolling_friction * c.r_eff * std::abs(fn);
      const double t_mag = torque.norm();
      if (t_mag > t_max) torque *= t_max / t_mag;
      return torque;
    }
  }
}

/// Cohesion sub-model: magnitude of the attractive normal force (>= 0).
/// sjkr: F = k A with A the area of the contact circle: for two spheres the
/// circle in which the two sphere surfaces intersect,
///   a^2 = delta (d + r_i - r_j)(d - r_i + r_j)(d + r_i + r_j) / (4 d^2),
///   d = r_i + r_j - delta,
/// for a wall (r_j = 0) the circle where the plane cuts the sphere,
///   a^2 = 2 r_i delta - delta^2;
/// A = pi a^2.
template <CohesionModel C>
[[gnu::always_inline]] inline double cohesion_force(const ContactState& c, const PairMaterial& m) {
  if constexpr (C == CohesionModel::Sjkr) {
    double a2;
    if (c.r_j > 0.0) {
      const double d = c.r_i + c.r_j - c.overlap;
      a2 = c.overlap * (d + c.r_i - c.r_j) * (d - c.r_i + c.r_j) * (d + c.r_i + c.r_j) / (4.0 * d * d);
    } else {
      a2 = c.overlap * (2.0 * c.r_i - c.overlap);
    }
    return m.cohesion_energy_density * M_PI * std::max(a2, 0.0);
  } else {
    (void)c, (void)m;
    return 0.0;
  }
}

}  // namespace detail

/// One contact with the sub-models fixed at compile time. Same contract as
/// evaluate(); `Limit` replaces spec.limit_force, `C` spec.cohesion, the other
/// spec switches (damping, tangential_damping, kt_to_kn_user,
/// tangential_reduce) are read at run time.
/// evaluate_prepared_t() takes the history-independent square roots from `q`
/// (detail::contact_roots() of the same contact).
template <NormalModel N, TangentialModel T, RollingModel R, bool Limit, CohesionModel C = CohesionModel::None>
[[gnu::always_inline]] inline void evaluate_prepared_t(const ModelSpec& spec, const ContactState& c,
                                                       const PairMaterial& m, const detail::Roots& q,
                                                       double* history, ContactResult& out) {
  constexpr int kShear = 0;
  constexpr int kRolling = detail::tangential_history_size<T>();
  constexpr int kSize = kRolling + detail::rolling_history_size<R>();

  out.torque_i.setZero();
  out.torque_j.setZero();
  out.ft.setZero();
  if (!(c.overlap > 0.0)) {
    out.force.setZero();
    out.fn = 0.0;
    for (int h = 0; h < kSize; ++h)
      history[h] = 0.0;
    return;
  }

  const detail::Coefficients k = detail::normal_coefficients<N>(spec, c, m, q);

  // Normal force: spring + dashpot; vn < 0 while approaching, so the dashpot
  // pushes the bodies apart on approach and pulls on separation.
  const double vn = c.v_rel.dot(c.n);
  const double fn_elastic = k.kn * c.overlap;
  double fn = fn_elastic - k.gamma_n * vn;
  if constexpr (Limit) {
    if (fn < 0.0) fn = 0.0;
  }
  // Cohesion pulls the bodies together after limitForce (which forbids only
  // the attraction of the dashpot). By default the Coulomb and rolling limits
  // below see the contact force without it (LIGGGHTS "tangential_reduce off").
  const double f_coh = detail::cohesion_force<C>(c, m);
  const double fn_total = fn - f_coh;
  if constexpr (C != CohesionModel::None) {
    if (spec.tangential_reduce) fn = std::max(fn_total, 0.0);  // net compression
  }
  out.fn = fn_total;
  out.force = fn_total * c.n;

  if constexpr (T != TangentialModel::None) {
    // Lever arms: the contact point lies in the middle of the overlap region,
    // at distance r - delta/2 from each centre (a wall has no lever arm).
    const double cr_i = c.r_i - 0.5 * c.overlap;
    const double cr_j = c.r_j > 0.0 ? c.r_j - 0.5 * c.overlap : 0.0;
    // Tangential relative velocity of the contact points: the tangential part
    // of the centre velocities minus the surface velocity from the spins,
    // (v_rel - vn n) - w x n. w x n already lies in the tangent plane, so no
    // second projection; this order of evaluation is LIGGGHTS', and it decides
    // the round-off that CDT rolling friction amplifies in symmetric packings.
    const Vec3 w = cr_i * c.omega_i + cr_j * c.omega_j;
    const Vec3 vt = (c.v_rel - vn * c.n) - w.cross(c.n);
    const Vec3 ft = detail::tangential_force<T>(c, m, k, fn, vt, history + kShear);
    out.ft = ft;
    out.force += ft;
    // ft acts on i at x_i - cr_i n and -ft on j at x_j + cr_j n.
    const Vec3 n_x_ft = c.n.cross(ft);
    out.torque_i = -cr_i * n_x_ft;
    out.torque_j = -cr_j * n_x_ft;
  }

  if constexpr (R != RollingModel::None) {
    const Vec3 mr = detail::rolling_torque<R>(c, m, k, q, fn, fn_elastic, history + kRolling);
    out.torque_i += mr;
    out.torque_j -= mr;
  }
}

template <NormalModel N, TangentialModel T, RollingModel R, bool Limit, CohesionModel C = CohesionModel::None>
[[gnu::always_inline]] inline void evaluate_t(const ModelSpec& spec, const ContactState& c,
                                              const PairMaterial& m, double* history, ContactResult& out) {
  detail::Roots q;
  if (c.overlap > 0.0) detail::contact_roots<N, R>(spec, c, m, q);
  evaluate_prepared_t<N, T, R, Limit, C>(spec, c, m, q, history, out);
}

/// A compiled kernel as a type, handed to the callback of dispatch_model().
template <NormalModel N, TangentialModel T, RollingModel R, bool Limit, CohesionModel C = CohesionModel::None>
struct Kernel {
  static constexpr NormalModel normal = N;
  static constexpr TangentialModel tangential = T;
  static constexpr RollingModel rolling = R;
  static constexpr bool limit_force = Limit;
  static constexpr CohesionModel cohesion = C;
  static constexpr int history_size =
      detail::tangential_history_size<T>() + detail::rolling_history_size<R>();
  [[gnu::always_inline]] static void evaluate(const ModelSpec& spec, const ContactState& c,
                                              const PairMaterial& m, double* history, ContactResult& out) {
    evaluate_t<N, T, R, Limit, C>(spec, c, m, history, out);
  }
  /// The square roots that do not depend on the history (see detail::Roots).
  [[gnu::always_inline]] static void roots(const ModelSpec& spec, const ContactState& c,
                                           const PairMaterial& m, detail::Roots& q) {
    detail::contact_roots<N, R>(spec, c, m, q);
  }
  [[gnu::always_inline]] static void evaluate_prepared(const ModelSpec& spec, const ContactState& c,
                                                       const PairMaterial& m, const detail::Roots& q,
                                                       double* history, ContactResult& out) {
    evaluate_prepared_t<N, T, R, Limit, C>(spec, c, m, q, history, out);
  }
};

namespace detail {

template <NormalModel N, TangentialModel T, RollingModel R, bool Limit, class Fn>
inline decltype(auto) dispatch_cohesion(const ModelSpec& s, Fn&& fn) {
  if (s.cohesion == CohesionModel::Sjkr) return fn(Kernel<N, T, R, Limit, CohesionModel::Sjkr>{});
  return fn(Kernel<N, T, R, Limit, CohesionModel::None>{});
}

template <NormalModel N, TangentialModel T, RollingModel R, class Fn>
inline decltype(auto) dispatch_limit(const ModelSpec& s, Fn&& fn) {
  if (s.limit_force) return dispatch_cohesion<N, T, R, true>(s, fn);
  return dispatch_cohesion<N, T, R, false>(s, fn);
}

template <NormalModel N, TangentialModel T, class Fn>
inline decltype(auto) dispatch_rolling(const ModelSpec& s, Fn&& fn) {
  switch (s.rolling) {
    case RollingModel::Cdt:
      return dispatch_limit<N, T, RollingModel::Cdt>(s, fn);
    case RollingModel::Epsd2:
      return dispatch_limit<N, T, RollingModel::Epsd2>(s, fn);
    case RollingModel::None:
      break;
  }
  return dispatch_limit<N, T, RollingModel::None>(s, fn);
}

template <NormalModel N, class Fn>
inline decltype(auto) dispatch_tangential(const ModelSpec& s, Fn&& fn) {
  switch (s.tangential) {
    case TangentialModel::None:
      return dispatch_rolling<N, TangentialModel::None>(s, fn);
    case TangentialModel::NoHistory:
      return dispatch_rolling<N, TangentialModel::NoHistory>(s, fn);
    case TangentialModel::History:
      break;
  }
  return dispatch_rolling<N, TangentialModel::History>(s, fn);
}

}  // namespace detail

/// Call fn(Kernel<...>{}) with the kernel type matching the runtime spec and
/// return what fn returns (fn must return the same type for every kernel).
template <class Fn>
inline decltype(auto) dispatch_model(const ModelSpec& spec, Fn&& fn) {
  if (spec.normal == NormalModel::Hooke) return detail::dispatch_tangential<NormalModel::Hooke>(spec, fn);
  return detail::dispatch_tangential<NormalModel::Hertz>(spec, fn);
}

}  // namespace granary::contact
