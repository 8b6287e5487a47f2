// A block of contacts evaluated in two stages, W at a time: the machinery the
// pair loop (pair/pair_loop.h) and the walls (fix wall/gran, primitive and
// mesh) share. The caller collects a block of contacts (pairs from the
// neighbour list, a particle and a wall), then evaluate_block():
//  1. for all contacts of the block, W at a time: the caller's `geometry`
//     fills the lanes' GeometryT and MaterialT; contact::prepare() (the square
//     roots and divisions that do not depend on the history: in one contact
//     they form a long chain of dependent slow operations, across contacts
//     they are independent and the processor overlaps them);
//  2. contact after contact in the block's order, W at a time: the caller's
//     `load` gathers spins, relative velocities and history, contact::interact(),
//     the caller's `store` writes the history back and adds the forces, for
//     the lanes that hold contacts (`nvalid`), in lane order; so the sums are
//     the same additions in the same order whatever W.
// A last group with fewer than W contacts repeats its last contact in the
// spare lanes; their results are not stored. The contacts of the block are
// named by their position c in the block (c[l]: the contact in lane l).
#pragma once

#include <algorithm>

#include "contact/contact_kernels.h"
#include "contact/lane.h"

namespace granary::contact {

/// The contacts of lanes m .. m+W-1 of a block of n (the last one repeated).
template <int W>
[[gnu::always_inline]] inline void block_lanes(int m, int n, int (&c)[W]) {
  for (int l = 0; l < W; ++l)
    c[l] = std::min(m + l, n - 1);
}

/// Lane l of the history state from the history doubles h of one contact.
template <class K, class S>
[[gnu::always_inline]] inline void load_history(const ModelSpec& spec, int l, const double* h,
                                                lane::V3<S>& shear, SlipT<S>& slip, lane::V3<S>& roll) {
  const int so = K::shear_offset(spec), po = K::slip_offset(spec), ro = K::rolling_offset(spec);
  const int ho = K::hysteresis_offset(spec);
  if (so >= 0) lane::set(shear, l, h + so);
  if (po >= 0) load_slip(slip, l, h + po);
  if (ro >= 0) lane::set(roll, l, h + ro);
  if (ho >= 0) lane::set(slip.d_max, l, h[ho]);
}

/// Lane l of the history state back into the history doubles h.
template <class K, class S>
[[gnu::always_inline]] inline void store_history(const ModelSpec& spec, int l, const lane::V3<S>& shear,
                                                 const SlipT<S>& slip, const lane::V3<S>& roll, double* h) {
  const int so = K::shear_offset(spec), po = K::slip_offset(spec), ro = K::rolling_offset(spec);
  const int ho = K::hysteresis_offset(spec);
  if (so >= 0) lane::store(shear, l, h + so);
  if (po >= 0) store_slip(slip, l, h + po);
  if (ro >= 0) lane::store(roll, l, h + ro);
  if (ho >= 0) h[ho] = lane::get(slip.d_max, l);
}

/// Evaluate the n contacts of a block (see the top of this file). `prep` holds
/// at least (n + W - 1) / W prepared groups. The callbacks, for the lanes'
/// contacts c[W]:
///   geometry(c, GeometryT<S>& g, MaterialT<S>& mat)
///   load(c, V3<S>& omega_i, V3<S>& v_rel, V3<S>& shear, SlipT<S>& slip, V3<S>& roll)
///     (shear, slip and roll arrive zero)
///   store(c, int nvalid, const ResultT<S>& out, shear, slip, roll)
template <class K, class S, class Geometry, class Load, class Store>
[[gnu::always_inline]] inline void evaluate_block(const ModelSpec& spec, int n, HistoryDt dt,
                                                  PreparedT<S>* prep, Geometry&& geometry, Load&& load,
                                                  Store&& store) {
  constexpr int W = lane::width<S>();
  for (int m = 0; m < n; m += W) {
    int c[W];
    block_lanes<W>(m, n, c);
    GeometryT<S> g;  // locals, so fields a model does not read cost nothing
    MaterialT<S> mat{};
    geometry(c, g, mat);
    prepare<K>(spec, g, mat, prep[m / W]);
  }
  ResultT<S> out;
  for (int m = 0; m < n; m += W) {
    int c[W];
    block_lanes<W>(m, n, c);
    lane::V3<S> omega_i = lane::zero3<S>(), v_rel = omega_i;  // filled by load
    lane::V3<S> shear = lane::zero3<S>(), roll = lane::zero3<S>();
    SlipT<S> slip{lane::splat<S>(0.0), lane::splat<S>(0.0), lane::splat<S>(0.0), lane::splat<S>(0.0)};
    load(c, omega_i, v_rel, shear, slip, roll);
    interact<K>(spec, prep[m / W], omega_i, v_rel, dt, shear, slip, roll, out);
    store(c, std::min(W, n - m), out, shear, slip, roll);
  }
}

}  // namespace granary::contact
