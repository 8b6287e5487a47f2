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
//     `load` gathers relative velocities and history, contact::interact(),
//     the results and the history go to memory lane by lane (GroupOut), and
//     the caller's `store` writes the history back and adds the forces, for
//     the lanes that hold contacts (`nvalid`), in lane order; so the sums are
//     the same additions in the same order whatever W.
// The contacts of the block are named by their position in the block: a
// group's lanes hold the contacts m .. m+W-1. The caller's arrays repeat the
// last contact up to the next multiple of W (pad_block()), so a last group
// with fewer than W contacts evaluates copies in its spare lanes; their
// results are not stored.
#pragma once

#include "contact/contact_kernels.h"
#include "contact/lane.h"

namespace granary::contact {

/// Repeat a[n-1] in a[n] .. up to the next multiple of W (n > 0; room for
/// W - 1 more than n).
template <int W, class T>
[[gnu::always_inline]] inline void pad_block(T* a, int n) {
  for (int k = n; k % W != 0; ++k)
    a[k] = a[n - 1];
}

/// The lanes' history state from the history doubles h[l] of each lane's contact.
template <class K, class S>
[[gnu::always_inline]] inline void load_history(const ModelSpec& spec,
                                                const double* const (&h)[lane::width<S>()],
                                                lane::V3<S>& shear, SlipT<S>& slip, lane::V3<S>& roll) {
  constexpr int W = lane::width<S>();
  const int so = K::shear_offset(spec), po = K::slip_offset(spec), ro = K::rolling_offset(spec);
  const int ho = K::hysteresis_offset(spec);
  const double* p[W];
  auto at = [&](int offset) __attribute__((always_inline)) {
    for (int l = 0; l < W; ++l)
      p[l] = h[l] + offset;
    return p;
  };
  if (so >= 0) shear = lane::gather3<S>(at(so));
  if (ro >= 0) roll = lane::gather3<S>(at(ro));
  for (int l = 0; l < W; ++l) {
    if (po >= 0) load_slip(slip, l, h[l] + po);
    if (ho >= 0) lane::set(slip.d_max, l, h[l][ho]);
  }
}

/// A group's results and history in memory, lane by lane: written once from
/// the registers by spill_group(), read a lane at a time by the callers' store.
/// (Lane l of a register, with l not known when compiling, makes the compiler
/// write the whole register to memory for every value read.)
template <class S>
struct GroupOut {
  static constexpr int W = lane::width<S>();
  double force[3][W], torque_i[3][W], torque_j[3][W], fn[W];
  double shear[3][W], roll[3][W], turn[W], t_max[W], kt_prev[W], d_max[W];
  /// lane l of one of the 3-vectors above
  static Eigen::Vector3d at(const double (&a)[3][W], int l) { return {a[0][l], a[1][l], a[2][l]}; }
};

/// The results of a group and the parts of its history the model keeps, into g.
template <class K, class S>
[[gnu::always_inline]] inline void spill_group(const ModelSpec& spec, const ResultT<S>& out,
                                               const lane::V3<S>& shear, const SlipT<S>& slip,
                                               const lane::V3<S>& roll, GroupOut<S>& g) {
  lane::spill(out.force, g.force);
  lane::spill(out.torque_i, g.torque_i);
  lane::spill(out.torque_j, g.torque_j);
  lane::spill(out.fn, g.fn);
  if (K::shear_offset(spec) >= 0) lane::spill(shear, g.shear);
  if (K::slip_offset(spec) >= 0) {
    lane::spill(slip.turn, g.turn);
    lane::spill(slip.t_max, g.t_max);
    lane::spill(slip.kt_prev, g.kt_prev);
  }
  if (K::rolling_offset(spec) >= 0) lane::spill(roll, g.roll);
  if (K::hysteresis_offset(spec) >= 0) lane::spill(slip.d_max, g.d_max);
}

/// Lane l of a group's history (spill_group()) back into the history doubles h.
template <class K, class S>
[[gnu::always_inline]] inline void store_history(const ModelSpec& spec, const GroupOut<S>& g, int l,
                                                 double* h) {
  const int so = K::shear_offset(spec), po = K::slip_offset(spec), ro = K::rolling_offset(spec);
  const int ho = K::hysteresis_offset(spec);
  for (int d = 0; d < 3; ++d) {
    if (so >= 0) h[so + d] = g.shear[d][l];
    if (ro >= 0) h[ro + d] = g.roll[d][l];
  }
  if (po >= 0) {
    h[po] = g.turn[l];
    h[po + 1] = g.t_max[l];
    h[po + 2] = g.kt_prev[l];
  }
  if (ho >= 0) h[ho] = g.d_max[l];
}

/// Evaluate the n contacts of a block (see the top of this file; the caller's
/// arrays padded by pad_block()). `prep` holds at least (n + W - 1) / W
/// prepared groups. The callbacks, for the group of lanes m .. m+W-1:
///   geometry(m, GeometryT<S>& g, MaterialT<S>& mat)
///   load(m, V3<S>& v_rel, V3<S>& shear, SlipT<S>& slip, V3<S>& roll)
///     (shear, slip and roll arrive zero)
///   store(m, int nvalid, const GroupOut<S>& r)   (results and history, lane by lane;
///     nvalid = W but in a last group of fewer contacts)
template <class K, class S, class Geometry, class Load, class Store>
[[gnu::always_inline]] inline void evaluate_block(const ModelSpec& spec, int n, HistoryDt dt,
                                                  PreparedT<S>* prep, Geometry&& geometry, Load&& load,
                                                  Store&& store) {
  constexpr int W = lane::width<S>();
  for (int m = 0; m < n; m += W) {
    GeometryT<S> g;  // locals, so fields a model does not read cost nothing
    MaterialT<S> mat{};
    geometry(m, g, mat);
    prepare<K>(spec, g, mat, prep[m / W]);
  }
  ResultT<S> out;
  GroupOut<S> r;
  for (int m = 0; m < n; m += W) {
    lane::V3<S> v_rel = lane::zero3<S>();  // filled by load
    lane::V3<S> shear = lane::zero3<S>(), roll = lane::zero3<S>();
    SlipT<S> slip{lane::splat<S>(0.0), lane::splat<S>(0.0), lane::splat<S>(0.0), lane::splat<S>(0.0)};
    load(m, v_rel, shear, slip, roll);
    interact<K>(spec, prep[m / W], v_rel, dt, shear, slip, roll, out);
    spill_group<K>(spec, out, shear, slip, roll, r);
    // (a full group's store with W known when compiling: 1.3 % fewer
    // instructions in the pair loop's second stages than one store for both)
    if (m + W <= n)
      store(m, W, r);
    else
      store(m, n - m, r);
  }
}

}  // namespace granary::contact
