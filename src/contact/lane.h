// The number types the contact formulas are written on: a plain double (one
// contact) or a lane of two doubles (two contacts at once, one per lane of a
// packed register). contact_kernels.h writes each sub-model once on a type S
// from this header; the pair loop picks the width.
//
//   S                 lanes  mask      on x86-64
//   double            1      bool      scalar SSE2 instructions
//   lane::D2          2      lane::M2  one SSE2 register (packed instructions)
//
// Branches of a formula become selections: select(m, a, b) is the ternary
// m ? a : b for a double and a per-lane bit selection for D2. Both sides of a
// selection are computed, so a division or square root on a discarded side
// may produce inf or NaN that never reaches a result. Every operation is the
// same IEEE operation in each lane, so a lane's result is the double's to the
// last bit (unittest/test_contact_lanes.cpp checks it).
//
// D2 uses the GCC/Clang vector extensions; elsewhere than x86-64 the compiler
// splits the operations. Apart from sqrt, any and all, the two-lane code is
// written for any width; four lanes (AVX2) gave the same bits but at most
// 4.5 % less pair time on the benchmarks (doc/performance.md), too little for
// a second build of the kernels chosen at run time.
#pragma once

#include <cmath>
#include <cstdint>
#include <type_traits>

#include <Eigen/Core>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace granary::contact::lane {

using D2 = double __attribute__((vector_size(16)));
using M2 = std::int64_t __attribute__((vector_size(16)));  ///< lane masks: all bits set = true

/// Number of lanes of S.
template <class S>
constexpr int width() {
  if constexpr (std::is_same_v<S, double>)
    return 1;
  else
    return static_cast<int>(sizeof(S) / sizeof(double));
}

/// The mask type of S (what a comparison of two S gives).
template <class S>
using Mask = std::conditional_t<std::is_same_v<S, double>, bool, M2>;

// ---- one lane: plain double ----------------------------------------------
[[gnu::always_inline]] inline double sqrt(double a) {
  return std::sqrt(a);
}
[[gnu::always_inline]] inline double abs(double a) {
  return std::fabs(a);
}
[[gnu::always_inline]] inline double select(bool m, double a, double b) {
  return m ? a : b;
}
[[gnu::always_inline]] inline bool any(bool m) {
  return m;
}
[[gnu::always_inline]] inline bool all(bool m) {
  return m;
}
[[gnu::always_inline]] inline bool mask_and(bool a, bool b) {
  return a & b;
}
[[gnu::always_inline]] inline bool mask_andnot(bool a, bool b) {  ///< !a and b
  return !a & b;
}
[[gnu::always_inline]] inline bool on(bool m, int) {
  return m;
}
[[gnu::always_inline]] inline double get(double a, int) {
  return a;
}
[[gnu::always_inline]] inline void set(double& a, int, double v) {
  a = v;
}
[[gnu::always_inline]] inline double pow(double a, double b) {
  return std::pow(a, b);
}
[[gnu::always_inline]] inline double cbrt(double a) {
  return std::cbrt(a);
}

// ---- two lanes ---------------------------------------------------------------
[[gnu::always_inline]] inline D2 sqrt(D2 a) {
#if defined(__SSE2__)
  return reinterpret_cast<D2>(_mm_sqrt_pd(reinterpret_cast<__m128d>(a)));
#else
  return D2{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
}
[[gnu::always_inline]] inline D2 abs(D2 a) {
  M2 mask;
  for (int l = 0; l < 2; ++l)
    mask[l] = INT64_MAX;
  return reinterpret_cast<D2>(reinterpret_cast<M2>(a) & mask);
}
[[gnu::always_inline]] inline D2 select(M2 m, D2 a, D2 b) {
  return reinterpret_cast<D2>((m & reinterpret_cast<M2>(a)) | (~m & reinterpret_cast<M2>(b)));
}
[[gnu::always_inline]] inline bool any(M2 m) {
  return (m[0] | m[1]) != 0;
}
[[gnu::always_inline]] inline bool all(M2 m) {
  return (m[0] & m[1]) != 0;
}
[[gnu::always_inline]] inline M2 mask_and(M2 a, M2 b) {
  return a & b;
}
[[gnu::always_inline]] inline M2 mask_andnot(M2 a, M2 b) {
  return ~a & b;
}
[[gnu::always_inline]] inline bool on(M2 m, int l) {
  return m[l] != 0;
}
[[gnu::always_inline]] inline double get(D2 a, int l) {
  return a[l];
}
[[gnu::always_inline]] inline void set(D2& a, int l, double v) {
  a[l] = v;
}
[[gnu::always_inline]] inline D2 pow(D2 a, double b) {
  return D2{std::pow(a[0], b), std::pow(a[1], b)};
}
[[gnu::always_inline]] inline D2 cbrt(D2 a) {
  return D2{std::cbrt(a[0]), std::cbrt(a[1])};
}

/// a in every lane of S.
template <class S>
[[gnu::always_inline]] inline S splat(double a) {
  if constexpr (std::is_same_v<S, double>) {
    return a;
  } else {
    S r;
    for (int l = 0; l < width<S>(); ++l)
      r[l] = a;
    return r;
  }
}

// ---- 3-vectors, one per lane ------------------------------------------------
// The operations in Eigen's order for 3-vectors (dot: (x + y) + z), so that a
// formula written on V3<double> gives what it gives on Eigen::Vector3d.
template <class S>
struct V3 {
  S x, y, z;
};
template <class S>
[[gnu::always_inline]] inline V3<S> operator+(const V3<S>& a, const V3<S>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class S>
[[gnu::always_inline]] inline V3<S> operator-(const V3<S>& a, const V3<S>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class S>
[[gnu::always_inline]] inline V3<S> operator*(S s, const V3<S>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class S, class = std::enable_if_t<!std::is_same_v<S, double>>>
[[gnu::always_inline]] inline V3<S> operator*(double s, const V3<S>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class S>
[[gnu::always_inline]] inline S dot(const V3<S>& a, const V3<S>& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
template <class S>
[[gnu::always_inline]] inline V3<S> cross(const V3<S>& a, const V3<S>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class S>
[[gnu::always_inline]] inline V3<S> select(Mask<S> m, const V3<S>& a, const V3<S>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}
template <class S>
[[gnu::always_inline]] inline V3<S> zero3() {
  return {splat<S>(0.0), splat<S>(0.0), splat<S>(0.0)};
}
/// Lane l as an Eigen vector, and back.
template <class S>
[[gnu::always_inline]] inline Eigen::Vector3d get(const V3<S>& a, int l) {
  return Eigen::Vector3d(get(a.x, l), get(a.y, l), get(a.z, l));
}
template <class S>
[[gnu::always_inline]] inline void set(V3<S>& a, int l, const Eigen::Vector3d& v) {
  set(a.x, l, v[0]);
  set(a.y, l, v[1]);
  set(a.z, l, v[2]);
}
template <class S>
[[gnu::always_inline]] inline void set(V3<S>& a, int l, const double* v) {
  set(a.x, l, v[0]);
  set(a.y, l, v[1]);
  set(a.z, l, v[2]);
}
template <class S>
[[gnu::always_inline]] inline void store(const V3<S>& a, int l, double* v) {
  v[0] = get(a.x, l);
  v[1] = get(a.y, l);
  v[2] = get(a.z, l);
}

/// Lanes of a[idx[0]], ..., a[idx[W-1]].
template <class S>
[[gnu::always_inline]] inline V3<S> gather(const Eigen::Vector3d* a, const int* idx) {
  V3<S> r;
  for (int l = 0; l < width<S>(); ++l)
    set(r, l, a[idx[l]]);
  return r;
}
template <class S>
[[gnu::always_inline]] inline S gather(const double* a, const int* idx) {
  S r;
  for (int l = 0; l < width<S>(); ++l)
    set(r, l, a[idx[l]]);
  return r;
}

}  // namespace granary::contact::lane
