// Two contacts at once: the Hertz / tangential history / (cdt or no) rolling
// kernel written on packed doubles, one contact per lane.
//
// This is the contact model of most LIGGGHTS scripts, and the pair loop
// spends most of a dense granular run in it. The scalar kernel
// (contact_kernels.h) stays the definition; this one performs the same IEEE
// operations in the same order in each lane, so a lane's result is the scalar
// kernel's to the last bit (unittest/test_contact_lanes.cpp checks it on
// random contacts). Branches of the scalar kernel become per-lane selections:
// both sides are computed and the lane's side kept, so a division or square
// root of a discarded side may produce inf or NaN that never reaches a result.
//
// Written with GCC/Clang vector extensions for W = 2 lanes: on x86-64 one
// SSE2 register (part of every x86-64 processor); elsewhere the compiler
// splits the operations. Apart from sqrt, any and all, the code is written
// for any W; four lanes (AVX2) were measured no faster on the benchmarks
// (doc/performance.md).
#pragma once

#include <cmath>
#include <cstdint>

#include "contact/contact_kernels.h"
#include "contact/contact_model.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace granary::contact::lanes {

/// True when contact_lanes can evaluate this kernel (pair loops check it at
/// compile time and keep the scalar kernel otherwise).
template <class Kernel>
constexpr bool supported() {
  return Kernel::normal == NormalModel::Hertz && Kernel::tangential == TangentialModel::History &&
         (Kernel::rolling == RollingModel::None || Kernel::rolling == RollingModel::Cdt) &&
         Kernel::cohesion == CohesionModel::None;
}

constexpr int W = 2;
using D = double __attribute__((vector_size(16)));
using M = std::int64_t __attribute__((vector_size(16)));  ///< lane masks: all bits set = true
[[gnu::always_inline]] inline D sqrt(D a) {
#if defined(__SSE2__)
  return reinterpret_cast<D>(_mm_sqrt_pd(reinterpret_cast<__m128d>(a)));
#else
  return D{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
}
[[gnu::always_inline]] inline bool any(M m) {
  return (m[0] | m[1]) != 0;
}
[[gnu::always_inline]] inline bool all(M m) {
  return (m[0] & m[1]) != 0;
}
[[gnu::always_inline]] inline D splat(double a) {
  D r;
  for (int l = 0; l < W; ++l)
    r[l] = a;
  return r;
}
[[gnu::always_inline]] inline D abs(D a) {
  M mask;
  for (int l = 0; l < W; ++l)
    mask[l] = INT64_MAX;
  return reinterpret_cast<D>(reinterpret_cast<M>(a) & mask);
}
[[gnu::always_inline]] inline D select(M m, D a, D b) {
  return reinterpret_cast<D>((m & reinterpret_cast<M>(a)) | (~m & reinterpret_cast<M>(b)));
}

/// A 3-vector per lane.
struct V3 {
  D x, y, z;
};
[[gnu::always_inline]] inline V3 operator+(const V3& a, const V3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
[[gnu::always_inline]] inline V3 operator-(const V3& a, const V3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
[[gnu::always_inline]] inline V3 operator*(D s, const V3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
[[gnu::always_inline]] inline V3 operator*(double s, const V3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
// Eigen's order for 3-vectors: (x + y) + z
[[gnu::always_inline]] inline D dot(const V3& a, const V3& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
[[gnu::always_inline]] inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
[[gnu::always_inline]] inline V3 select(M m, const V3& a, const V3& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}
/// Lane l of a V3 as an Eigen vector.
[[gnu::always_inline]] inline Vec3 lane(const V3& a, int l) {
  return Vec3(a.x[l], a.y[l], a.z[l]);
}
/// Lanes of a[idx[0]], ..., a[idx[W-1]].
[[gnu::always_inline]] inline V3 gather(const Vec3* a, const int* idx) {
  V3 r;
  for (int l = 0; l < W; ++l) {
    r.x[l] = a[idx[l]][0];
    r.y[l] = a[idx[l]][1];
    r.z[l] = a[idx[l]][2];
  }
  return r;
}
[[gnu::always_inline]] inline D gather(const double* a, const int* idx) {
  D r;
  for (int l = 0; l < W; ++l)
    r[l] = a[idx[l]];
  return r;
}

/// What prepare() reads for W contacts (of one particle i or of several).
struct PairInput {
  V3 d;          ///< x_i - x_j
  D r_i{};       ///< radii of the particles i
  D r_j{};       ///< radii of the partners (> 0)
  D m_i{};       ///< masses of the particles i
  D m_j{};       ///< masses of the partners
  V3 omega_i;    ///< spins of the particles i
  V3 omega_j;    ///< spins of the partners
  D r_eff{};     ///< r_i r_j / (r_i + r_j): effective_radius_mass()
  D m_eff{};     ///< m_i m_j / (m_i + m_j)
  D Y_eff{}, G_eff{}, beta{}, friction{}, rolling_friction{}, dissipative_time{};  ///< PairMaterial fields
};

/// What W contacts need from the first stage (prepare()): the
/// geometry, the history-independent coefficients and the partners' data the
/// second stage would otherwise gather again.
struct Prepared {
  V3 n;                         ///< unit normal from j to i
  D overlap, r_eff;
  D kn, kt, gamma_n, gamma_t;  ///< normal_coefficients<Hertz>
  D cr_i, cr_j;                ///< lever arms r - overlap/2
  D friction, rolling_friction;
  V3 omega_j;                   ///< spins of the partners
  D spin;                      ///< |omega_i - omega_j| (cdt)
};

struct PairOutput {
  V3 force;     ///< on i (the partner receives -force)
  V3 torque_i;  ///< on i
  V3 torque_j;  ///< on the partner
};

/// R* and m* of PairInput, as the scalar pair loop computes them. The two
/// divisions depend on the partners' radii and masses only; in a bed of equal
/// particles they repeat, and a caller may keep the last result.
[[gnu::always_inline]] inline void effective_radius_mass(PairInput& in) {
  in.r_eff = in.r_i * in.r_j / (in.r_i + in.r_j);
  in.m_eff = in.m_i * in.m_j / (in.m_i + in.m_j);
}

/// First stage of hertz_history(): geometry (n = d * (1/r), overlap, lever
/// arms), the square roots of detail::contact_roots_lanes and
/// normal_coefficients<Hertz>. Reads d, r_i, r_j, r_eff, m_eff, the materials
/// and the spins. None of it depends on the contact history, so a pair loop
/// runs this stage over all contacts of a particle first: the chains of square
/// roots of different contacts are independent and overlap in the processor.
template <RollingModel R>
[[gnu::always_inline]] inline void prepare(const ModelSpec& spec, const PairInput& in, Prepared& q) {
  static_assert(R == RollingModel::None || R == RollingModel::Cdt, "contact_lanes: rolling none or cdt");
  const D r = sqrt(dot(in.d, in.d));
  const D inv_r = 1.0 / r;
  const D rsum = in.r_i + in.r_j;
  const D overlap = rsum - r;
  q.overlap = overlap;
  q.r_eff = in.r_eff;
  const D sqrtval = sqrt(in.r_eff * overlap);
  const D sn = 2.0 * in.Y_eff * sqrtval;
  const D st = 8.0 * in.G_eff * sqrtval;
  q.kn = (4.0 / 3.0) * in.Y_eff * sqrtval;
  q.kt = st;
  if (spec.damping == DampingModel::Viscoelastic) {
    q.gamma_n = in.dissipative_time * sn;
    q.gamma_t = in.dissipative_time * st;
  } else {
    const D root_n = sqrt(sn * in.m_eff);
    const D root_t = sqrt(st * in.m_eff);
    q.gamma_n = -2.0 * detail::kSqrtFiveSixths * in.beta * root_n;
    q.gamma_t = -2.0 * detail::kSqrtFiveSixths * in.beta * root_t;
  }
  if (!spec.tangential_damping) q.gamma_t = splat(0.0);
  q.n = {in.d.x * inv_r, in.d.y * inv_r, in.d.z * inv_r};
  q.cr_i = in.r_i - 0.5 * overlap;
  q.cr_j = in.r_j - 0.5 * overlap;
  q.friction = in.friction;
  q.rolling_friction = in.rolling_friction;
  q.omega_j = in.omega_j;
  if constexpr (R == RollingModel::Cdt) {
    const V3 wr = in.omega_i - in.omega_j;
    q.spin = sqrt(dot(wr, wr));
  } else {
    q.spin = splat(0.0);
  }
}

/// The pair contact of evaluate_prepared_t<Hertz, History, R, Limit, None>
/// for W contacts, from the first stage's `q`, the relative velocity
/// `v_rel`, the spins of the particles i and the timestep. `shear` is the tangential
/// displacement history, updated in place; a lane whose overlap is not
/// positive gets a zero result and a zero history, as in the scalar kernel.
template <RollingModel R, bool Limit>
[[gnu::always_inline]] inline void hertz_history(const Prepared& q, const V3& v_rel, const V3& omega_i,
                                                 double dt, V3& shear, PairOutput& out) {
  static_assert(R == RollingModel::None || R == RollingModel::Cdt, "contact_lanes: rolling none or cdt");
  const D overlap = q.overlap;
  const D kt = q.kt;
  const D gamma_t = q.gamma_t;
  const V3 n = q.n;
  const D vn = dot(v_rel, n);
  const D fn_elastic = q.kn * overlap;
  D fn = fn_elastic - q.gamma_n * vn;
  if constexpr (Limit) fn = select(fn < 0.0, splat(0.0), fn);
  V3 force = fn * n;

  // tangential: contact-point velocity, history spring (tangential_force<History>)
  const V3 w = q.cr_i * omega_i + q.cr_j * q.omega_j;
  const V3 vt = (v_rel - vn * n) - cross(w, n);
  const D ft_max = q.friction * abs(fn);
  V3 s = shear + dt * vt;
  const D sn_dot = dot(s, n);
  s = s - sn_dot * n;
  const D minus_kt = -kt;
  V3 ft = minus_kt * s;
  const D ft_spring = kt * sqrt(dot(s, s));
  const M slip = ft_spring > ft_max;
  if (any(slip)) {
    // four divisions per lane: only when a lane slips (in a resting bed, rarely)
    const V3 ft_slip = (ft_max / ft_spring) * ft;
    const V3 s_slip = {ft_slip.x / minus_kt, ft_slip.y / minus_kt, ft_slip.z / minus_kt};
    ft = select(slip, ft_slip, ft - gamma_t * vt);
    s = select(slip, s_slip, s);
  } else {
    ft = ft - gamma_t * vt;
  }
  force = force + ft;
  const V3 n_x_ft = cross(n, ft);
  V3 torque_i = -q.cr_i * n_x_ft;
  V3 torque_j = -q.cr_j * n_x_ft;

  if constexpr (R == RollingModel::Cdt) {
    // rolling_torque<Cdt>
    V3 wr = omega_i - q.omega_j;
    const D w_full = q.spin;
    wr = wr - dot(wr, n) * n;
    const D w2 = w_full * w_full;
    const D s2 = dot(omega_i, omega_i) + dot(q.omega_j, q.omega_j);
    constexpr double tol = detail::kRollingSpinTolerance;
    const M clearly = w2 > 4.0 * tol * tol * s2;
    M none = M{};
    if (!all(clearly)) {
      // rare: spins equal to round-off
      const D bound = tol * (sqrt(dot(omega_i, omega_i)) + sqrt(dot(q.omega_j, q.omega_j)));
      none = ~clearly & (w_full <= bound);
    }
    const D scale = -q.rolling_friction * fn_elastic * q.r_eff / w_full;
    const V3 mr = select(none, V3{splat(0.0), splat(0.0), splat(0.0)}, scale * wr);
    torque_i = torque_i + mr;
    torque_j = torque_j - mr;
  }

  const M touching = overlap > 0.0;
  const V3 zero{splat(0.0), splat(0.0), splat(0.0)};
  out.force = select(touching, force, zero);
  out.torque_i = select(touching, torque_i, zero);
  out.torque_j = select(touching, torque_j, zero);
  shear = select(touching, s, zero);
}


}  // namespace granary::contact::lanes
