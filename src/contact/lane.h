// The number types the contact formulas are written on: a plain double (one
// contact) or a lane of two or four doubles (two or four contacts at once, one
// per lane of a packed register). contact_kernels.h writes each sub-model once
// on a type S from this header; the pair loop and the walls take lane::Wide.
//
//   S                 lanes  mask      on x86-64
//   double            1      bool      scalar SSE2 instructions
//   lane::D2          2      lane::M2  one SSE2 register (packed instructions)
//   lane::D4          4      lane::M4  one AVX register (a build with AVX2;
//                                      otherwise the compiler splits it in two)
//
// Branches of a formula become selections: select(m, a, b) is the ternary
// m ? a : b for a double and a per-lane bit selection for D2 and D4. Both
// sides of a selection are computed, so a division or square root on a
// discarded side may produce inf or NaN that never reaches a result. Every
// operation is the same IEEE operation in each lane (no fused multiply-add:
// a build for AVX2 does not enable FMA), so a lane's result is the double's to
// the last bit, whatever the width (unittest/test_contact_lanes.cpp checks it).
//
// D2 and D4 use the GCC/Clang vector extensions; elsewhere than x86-64 the
// compiler splits the operations. lane::Wide is D4 in a build for AVX2 (CMake
// option GRANARY_SIMD, doc/install.md) and D2 otherwise.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include <Eigen/Core>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif
#if defined(__AVX__)
#include <immintrin.h>
#endif

// Without AVX, GCC notes (-Wpsabi) that D4 and M4 passed by value have
// another ABI than with it; every function here is inlined, so no call
// crosses a boundary where that could matter.
#if !defined(__AVX__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#define GRANARY_LANE_PSABI_PUSHED
#endif

namespace granary::contact::lane {

using D2 = double __attribute__((vector_size(16)));
using M2 = std::int64_t __attribute__((vector_size(16)));  ///< lane masks: all bits set = true
using D4 = double __attribute__((vector_size(32)));
using M4 = std::int64_t __attribute__((vector_size(32)));
#if defined(__AVX2__)
using Wide = D4;  ///< the lane type of the pair loop and the walls in this build
#else
using Wide = D2;
#endif

/// Number of lanes of S (of a mask type too: its lanes are 8-byte integers).
template <class S>
constexpr int width() {
  if constexpr (std::is_same_v<S, double>)
    return 1;
  else
    return static_cast<int>(sizeof(S) / sizeof(double));
}

/// The mask type of S (what a comparison of two S gives).
template <class S>
using Mask =
    std::conditional_t<std::is_same_v<S, double>, bool, std::conditional_t<std::is_same_v<S, D2>, M2, M4>>;

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

// ---- several lanes: D2, D4 -------------------------------------------------
/// True for the packed lane types (their masks are the int64 vectors of the same size).
template <class S>
constexpr bool packed = std::is_same_v<S, D2> || std::is_same_v<S, D4>;

template <class S, class = std::enable_if_t<packed<S>>>
[[gnu::always_inline]] inline S sqrt(S a) {
#if defined(__AVX__)
  if constexpr (std::is_same_v<S, D4>)
    return reinterpret_cast<D4>(_mm256_sqrt_pd(reinterpret_cast<__m256d>(a)));
#endif
#if defined(__SSE2__)
  if constexpr (std::is_same_v<S, D2>) return reinterpret_cast<D2>(_mm_sqrt_pd(reinterpret_cast<__m128d>(a)));
#endif
  S r;
  for (int l = 0; l < width<S>(); ++l)
    r[l] = std::sqrt(a[l]);
  return r;
}
template <class S, class = std::enable_if_t<packed<S>>>
[[gnu::always_inline]] inline S abs(S a) {
  Mask<S> mask;
  for (int l = 0; l < width<S>(); ++l)
    mask[l] = INT64_MAX;
  return reinterpret_cast<S>(reinterpret_cast<Mask<S>>(a) & mask);
}
template <class S, class = std::enable_if_t<packed<S>>>
[[gnu::always_inline]] inline S select(Mask<S> m, S a, S b) {
  return reinterpret_cast<S>((m & reinterpret_cast<Mask<S>>(a)) | (~m & reinterpret_cast<Mask<S>>(b)));
}
// The masks' operations are plain overloads for M2 and M4, not templates: a
// comparison of two D2 gives a vector of long with GCC and of long long with
// Clang, which converts to M2 or M4 but would not deduce a template's type.
// A mask's lanes are all bits set or none (what comparisons, mask_and and
// mask_andnot give), so the sign bit of a lane says it: bits() reads the
// sign bits in one instruction (movmskpd) instead of a lane at a time.
template <class M>
[[gnu::always_inline]] inline int sign_bits(M m) {
  int r = 0;
  for (int l = 0; l < width<M>(); ++l)
    r |= static_cast<int>(m[l] < 0) << l;
  return r;
}
/// The lanes of a mask as the bits of an int: bit l set when lane l is true.
[[gnu::always_inline]] inline int bits(bool m) {
  return m;
}
[[gnu::always_inline]] inline int bits(M2 m) {
#if defined(__SSE2__)
  return _mm_movemask_pd(reinterpret_cast<__m128d>(m));
#else
  return sign_bits(m);
#endif
}
[[gnu::always_inline]] inline int bits(M4 m) {
#if defined(__AVX__)
  return _mm256_movemask_pd(reinterpret_cast<__m256d>(m));
#else
  return sign_bits(m);
#endif
}
[[gnu::always_inline]] inline bool any(M2 m) {
  return bits(m) != 0;
}
[[gnu::always_inline]] inline bool any(M4 m) {
  return bits(m) != 0;
}
[[gnu::always_inline]] inline bool all(M2 m) {
  return bits(m) == 3;
}
[[gnu::always_inline]] inline bool all(M4 m) {
  return bits(m) == 15;
}
[[gnu::always_inline]] inline M2 mask_and(M2 a, M2 b) {
  return a & b;
}
[[gnu::always_inline]] inline M4 mask_and(M4 a, M4 b) {
  return a & b;
}
[[gnu::always_inline]] inline M2 mask_andnot(M2 a, M2 b) {
  return ~a & b;
}
[[gnu::always_inline]] inline M4 mask_andnot(M4 a, M4 b) {
  return ~a & b;
}
template <class S, class = std::enable_if_t<packed<S>>>
[[gnu::always_inline]] inline double get(S a, int l) {
  return a[l];
}
template <class S, class = std::enable_if_t<packed<S>>>
[[gnu::always_inline]] inline void set(S& a, int l, double v) {
  a[l] = v;
}
template <class S, class = std::enable_if_t<packed<S>>>
[[gnu::always_inline]] inline S pow(S a, double b) {
  S r;
  for (int l = 0; l < width<S>(); ++l)
    r[l] = std::pow(a[l], b);
  return r;
}
template <class S, class = std::enable_if_t<packed<S>>>
[[gnu::always_inline]] inline S cbrt(S a) {
  S r;
  for (int l = 0; l < width<S>(); ++l)
    r[l] = std::cbrt(a[l]);
  return r;
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

/// The lanes of a into out[0 .. W-1]; of a 3-vector into out[0][...], out[1][...], out[2][...].
template <class S>
[[gnu::always_inline]] inline void spill(S a, double* out) {
  if constexpr (std::is_same_v<S, double>)
    out[0] = a;
  else
    std::memcpy(out, &a, sizeof a);
}
template <class S>
[[gnu::always_inline]] inline void spill(const V3<S>& a, double (&out)[3][width<S>()]) {
  spill(a.x, out[0]);
  spill(a.y, out[1]);
  spill(a.z, out[2]);
}

/// Lanes of the 3-vectors at p[0], ..., p[W-1] (three doubles each). Four
/// lanes: x and y of two vectors per 256-bit register, then unpacked (11
/// instructions instead of 15), reading no byte beyond the vectors.
template <class S>
[[gnu::always_inline]] inline V3<S> gather3(const double* const* p) {
#if defined(__AVX__)
  if constexpr (std::is_same_v<S, D4>) {
    const __m256d ac =
        _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p[0])), _mm_loadu_pd(p[2]), 1);
    const __m256d bd =
        _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p[1])), _mm_loadu_pd(p[3]), 1);
    const __m128d z01 = _mm_loadh_pd(_mm_load_sd(p[0] + 2), p[1] + 2);
    const __m128d z23 = _mm_loadh_pd(_mm_load_sd(p[2] + 2), p[3] + 2);
    return {reinterpret_cast<D4>(_mm256_unpacklo_pd(ac, bd)),
            reinterpret_cast<D4>(_mm256_unpackhi_pd(ac, bd)),
            reinterpret_cast<D4>(_mm256_insertf128_pd(_mm256_castpd128_pd256(z01), z23, 1))};
  }
#endif
  V3<S> r;
  for (int l = 0; l < width<S>(); ++l)
    set(r, l, p[l]);
  return r;
}

/// Lanes of a[idx[0]], ..., a[idx[W-1]].
template <class S>
[[gnu::always_inline]] inline V3<S> gather(const Eigen::Vector3d* a, const int* idx) {
  const double* p[width<S>()];
  for (int l = 0; l < width<S>(); ++l)
    p[l] = a[idx[l]].data();
  return gather3<S>(p);
}
template <class S>
[[gnu::always_inline]] inline S gather(const double* a, const int* idx) {
  S r;
  for (int l = 0; l < width<S>(); ++l)
    set(r, l, a[idx[l]]);
  return r;
}

/// The lanes l of W (1, 2 or 4) whose a[idx[l]] is not negative, as the bits
/// of an int (bit l for lane l): with four lanes one vector of the four values
/// and its sign bits (movmskps) instead of a test and a shift per lane.
template <int W>
[[gnu::always_inline]] inline int nonnegative_bits(const std::int32_t* a, const int* idx) {
#if defined(__SSE4_1__)
  if constexpr (W == 4) {
    __m128i v = _mm_cvtsi32_si128(a[idx[0]]);
    v = _mm_insert_epi32(v, a[idx[1]], 1);
    v = _mm_insert_epi32(v, a[idx[2]], 2);
    v = _mm_insert_epi32(v, a[idx[3]], 3);
    return ~_mm_movemask_ps(_mm_castsi128_ps(v)) & 0xF;
  }
#endif
  int r = 0;
  for (int l = 0; l < W; ++l)
    r |= static_cast<int>(a[idx[l]] >= 0) << l;
  return r;
}

/// The same for a[0 .. W-1].
template <int W>
[[gnu::always_inline]] inline int nonnegative_bits(const std::int32_t* a) {
#if defined(__SSE2__)
  if constexpr (W == 4) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a));
    return ~_mm_movemask_ps(_mm_castsi128_ps(v)) & 0xF;
  }
#endif
  int r = 0;
  for (int l = 0; l < W; ++l)
    r |= static_cast<int>(a[l] >= 0) << l;
  return r;
}

/// The lanes l of W (1, 2 or 4) of a[] set in t to out[0 ..] in lane order;
/// returns how many lanes are set. Any of out[0 .. W-1] may be written: what
/// follows the set lanes is to be overwritten by what is stored next, or lie
/// past the end. With four lanes and AVX one permutation of the four values
/// (the set lanes first) and one store, instead of a position and a store per
/// lane.
template <int W>
[[gnu::always_inline]] inline int compress(const std::int32_t* a, int t, std::int32_t* out) {
  // below[t][l]: how many of the lanes 0 .. l-1 are set in t (l = W: all)
  static constexpr auto below = [] {
    std::array<std::array<std::int8_t, W + 1>, (1 << W)> c{};
    for (int u = 0; u < (1 << W); ++u)
      for (int l = 0; l < W; ++l)
        c[u][l + 1] = static_cast<std::int8_t>(c[u][l] + ((u >> l) & 1));
    return c;
  }();
#if defined(__AVX__)
  if constexpr (W == 4) {
    static constexpr auto order = [] {
      std::array<std::array<std::int32_t, 4>, 16> c{};
      for (int u = 0; u < 16; ++u) {
        int at = 0;
        for (int l = 0; l < 4; ++l)
          if ((u >> l) & 1) c[u][at++] = l;
        for (int l = 0; l < 4; ++l)
          if (!((u >> l) & 1)) c[u][at++] = l;
      }
      return c;
    }();
    // (from the values, not a load: a[] may be a local array whose values are
    // still in registers; where it is memory, the compiler makes one load)
    const __m128 v = _mm_castsi128_ps(_mm_setr_epi32(a[0], a[1], a[2], a[3]));
    const __m128i o = _mm_loadu_si128(reinterpret_cast<const __m128i*>(order[t].data()));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_castps_si128(_mm_permutevar_ps(v, o)));
    return below[t][W];
  }
#endif
  for (int l = 0; l < W; ++l)
    out[below[t][l]] = a[l];
  return below[t][W];
}

/// W consecutive doubles p[0 .. W-1] as the lanes of S.
template <class S>
[[gnu::always_inline]] inline S load(const double* p) {
  if constexpr (std::is_same_v<S, double>) {
    return *p;
  } else {
    S r;
    std::memcpy(&r, p, sizeof r);
    return r;
  }
}

/// 64-bit integers, one per lane of S (for a double, one).
template <class S>
using Ints = std::conditional_t<std::is_same_v<S, double>, std::int64_t, Mask<S>>;
/// a in every lane.
template <class S>
[[gnu::always_inline]] inline Ints<S> splat_int(std::int64_t a) {
  if constexpr (std::is_same_v<S, double>) {
    return a;
  } else {
    Ints<S> r;
    for (int l = 0; l < width<S>(); ++l)
      r[l] = a;
    return r;
  }
}
/// The lanes l whose k[l] (W consecutive 64-bit integers) differs from
/// key's, as the bits of an int.
template <class S>
[[gnu::always_inline]] inline int differ_bits(const std::int64_t* k, Ints<S> key) {
  if constexpr (std::is_same_v<S, double>) {
    return *k != key;
  } else {
    Ints<S> v;
    std::memcpy(&v, k, sizeof v);
    // (the lanes that are equal, inverted: a comparison for "not equal" is
    // one for equal and a negation of the mask)
    return ~bits(static_cast<Mask<S>>(v == key)) & ((1 << width<S>()) - 1);
  }
}

}  // namespace granary::contact::lane

#ifdef GRANARY_LANE_PSABI_PUSHED
#pragma GCC diagnostic pop
#undef GRANARY_LANE_PSABI_PUSHED
#endif
