// The neighbour loop of the granular pair styles: one loop for every contact
// model and both widths. It is templated on the sub-model slots K
// (contact_kernels.h: a compiled hot kernel or RuntimeKernel) and on the
// number type S (double: one contact at a time; lane::D2: two; lane::D4: four).
//
// In blocks of about kPairBlock contacts:
//  1. all list entries (or those of the caller's near list: the entries that
//     can touch before it is remade, with their two particles) as one
//     stream, W at a time: which touch, without a branch per entry (whether a
//     listed pair touches is close to a coin toss in a dense bed, and a
//     mispredicted branch per entry costs more than the distance test
//     itself); a contact that began takes a history slot, one that ended
//     returns its slot; the contacts are appended to the block with their two
//     particles; when the caller asks for a new near list, the scan of all
//     entries writes it on the way (the same way: no branch);
//  2. for all contacts of the block, W at a time (lanes may hold contacts of
//     different particles): geometry and contact::prepare() (the square roots
//     and divisions that do not depend on the history: in one contact they form
//     a long chain of dependent slow operations, across contacts they are
//     independent and the processor overlaps them);
//  3. contact::interact() and the sums, contact after contact in the list's
//     order, so the sums are the same additions in the same order whatever W.
// Long stretches of entries and contacts instead of a particle's few keep the
// loops from ending (a mispredicted branch) at every particle. A last group
// with fewer than W contacts repeats its last contact in the spare lanes;
// their results are not used. The results are the same to the last bit for
// every W (unittest/test_pair_lane_loop.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "contact/contact_block.h"
#include "contact/contact_kernels.h"
#include "contact/lane.h"
#include "core/vec3.h"
#include "neighbor/contact_history.h"
#include "pair/multicontact.h"
#include "pair/materials.h"
#include "particles/particles.h"

namespace granary {

/// What the pair loop reads and writes.
struct PairLoopData {
  int nlocal = 0;
  bool newton = false;
  const int* offset = nullptr;  ///< list entries of particle i: offset[i] .. offset[i+1]
  const int* neigh = nullptr;
  const int* owner = nullptr;  ///< particle of each list entry
  const Vec3* x = nullptr;
  const Vec3* v = nullptr;
  const Vec3* omega = nullptr;
  Vec3* f = nullptr;
  Vec3* torque = nullptr;
  const double* radius = nullptr;
  const double* rmass = nullptr;
  const double* body_mass = nullptr;  ///< null without clumps
  const int* type = nullptr;
  /// models with history: a slot per list entry, taken when the pair begins
  /// to touch and returned when the contact ends
  ContactHistory* history = nullptr;
  const MaterialTable* materials = nullptr;
  const contact::ModelSpec* spec = nullptr;
  contact::HistoryDt dt;  ///< timesteps of the history integration
  /// "surface multicontact": the fix that changes the overlaps and records the
  /// contacts (null otherwise), and the particles it reads
  MultiContact* mc = nullptr;
  const Particles* particles = nullptr;
  /// optional near list: the list entries (ascending) that can touch before
  /// the caller remakes it, their two particles (owner[near[q]] and
  /// neigh[near[q]]) and, with history, their slots (slots()[near[q]], kept
  /// equal to it: stage 1 writes both when a contact begins or ends); all
  /// copied to be read in step with near, not through it; with use_near
  /// stage 1 scans only these (none when nnear is 0), else every entry
  bool use_near = false;
  const int* near = nullptr;
  const int* near_i = nullptr;
  const int* near_j = nullptr;
  std::int32_t* near_slot = nullptr;
  int nnear = 0;
  /// or, to make the near list anew: every entry is scanned and those whose
  /// spheres are within near_margin of touching are written here, ascending
  /// (room for all entries, plus the lanes of one group); pair_loop() returns
  /// their number
  int* near_out = nullptr;
  double near_margin = 0.0;
};

constexpr int kPairBlock = 64;

/// The pair loop (see the top of this file); returns the number of entries
/// written to L.near_out (0 without).
template <class K, class S>
int pair_loop(const PairLoopData& L) {
  using namespace contact;
  using lane::V3;
  constexpr int W = lane::width<S>();
  const ModelSpec spec = *L.spec;
  const int nh = K::history_size(spec);
  const int nlocal = L.nlocal;
  const int* const neigh = L.neigh;
  const Vec3* const x = L.x;
  const Vec3* const v = L.v;
  const Vec3* const omega = L.omega;
  Vec3* const f = L.f;
  Vec3* const torque = L.torque;
  const double* const radius = L.radius;
  const double* const rmass = L.rmass;
  const double* const body_mass = L.body_mass;
  const int* const type = L.type;
  ContactHistory* const history = L.history;
  std::int32_t* const slot = nh > 0 ? history->slots() : nullptr;
  constexpr std::int32_t kNone = ContactHistory::kNone;
  const MaterialTable& materials = *L.materials;
  const contact::HistoryDt dt = L.dt;
  const bool newton = L.newton;
  MultiContact* const mc = L.mc;
  // the block: list position and the two particles of each contact, the
  // first stage's results; fewer than kPairBlock contacts before the last
  // group of W entries, and room for the copies of the last contact that
  // fill the last group (pad_block())
  constexpr int kCap = kPairBlock + W;
  int blk_k[kCap], blk_i[kCap], blk_j[kCap];
  PreparedT<S> prep[(kCap + W - 1) / W];

  // one type pair: the lanes' material set once for all contacts
  const bool one_material = materials.ntypes() == 1;
  MaterialT<S> material{};
  if (one_material) {
    const PairMaterial* pm[W];
    for (int l = 0; l < W; ++l)
      pm[l] = &materials(1, 1);
    set_materials(material, pm);
  }

  // stages 2 and 3 for the n contacts of the block (contact/contact_block.h)
  // (the pointers and flags by value: one load each from the closure, not two)
  auto flush = [&, f, torque, x, v, omega, radius, rmass, body_mass, type, slot, newton, nlocal, mc,
                one_material](int n) {
    pad_block<W>(blk_k, n);
    pad_block<W>(blk_i, n);
    pad_block<W>(blk_j, n);
    // (stage 1 took the slots of this block's new contacts: the pool stays put until the next block)
    double* const pool = nh > 0 ? history->pool() : nullptr;
    // R* and m* again only for pairs unlike the last group's (exact
    // comparisons: the same operands give the same quotients); radii are
    // positive, so nothing matches at first
    S last_ri = lane::splat<S>(-1.0), last_rj = last_ri, last_mi = last_ri, last_mj = last_ri;
    S r_eff = last_ri, m_eff = last_ri;
    auto geometry = [&](int m, GeometryT<S>& g, MaterialT<S>& mat) __attribute__((always_inline)) {
      const int* const ii = blk_i + m;
      const int* const j = blk_j + m;
      const V3<S> d = lane::gather<S>(x, ii) - lane::gather<S>(x, j);
      const S r_i = lane::gather<S>(radius, ii);
      const S r_j = lane::gather<S>(radius, j);
      S m_i, m_j;
      if (body_mass) {
        // sub-spheres of clumps use their body's mass (filled by fix multisphere)
        auto mass = [&](int a) { return body_mass[a] > 0.0 ? body_mass[a] : rmass[a]; };
        for (int l = 0; l < W; ++l) {
          lane::set(m_i, l, mass(ii[l]));
          lane::set(m_j, l, mass(j[l]));
        }
      } else {  // no clumps: every particle's own mass
        m_i = lane::gather<S>(rmass, ii);
        m_j = lane::gather<S>(rmass, j);
      }
      if (!lane::all(lane::mask_and(lane::mask_and(r_i == last_ri, r_j == last_rj),
                                    lane::mask_and(m_i == last_mi, m_j == last_mj)))) {
        r_eff = r_i * r_j / (r_i + r_j);
        m_eff = m_i * m_j / (m_i + m_j);
        last_ri = r_i;
        last_rj = r_j;
        last_mi = m_i;
        last_mj = m_j;
      }
      // 1/r, then n = d * (1/r), not d / r: the same rounding as LIGGGHTS
      // (round-off spins feed the cdt rolling torque, so the last bit matters)
      const S r = lane::sqrt(dot(d, d));
      const S inv_r = 1.0 / r;
      g.n = {d.x * inv_r, d.y * inv_r, d.z * inv_r};
      g.overlap = (r_i + r_j) - r;
      g.r_i = r_i;
      g.r_j = r_j;
      g.r_eff = r_eff;
      g.m_eff = m_eff;
      if (mc) {
        // multicontact: the radii of i and j changed by the deformation that
        // their other contacts cause at this contact's point (the middle of
        // the overlap; n points from j to i); the contact law sees the new
        // radii: overlap, R* and lever arms
        const Particles& P = *L.particles;
        S ri_new = r_i, rj_new = r_j;
        for (int l = 0; l < W; ++l) {
          const Vec3 nl = lane::get(g.n, l);
          const double ri = lane::get(r_i, l), ov = lane::get(g.overlap, l);
          const Vec3 point = x[ii[l]] + MultiContact::offset(ri, ov, nl);
          lane::set(ri_new, l, ri + mc->shift(P, ii[l], static_cast<double>(P.id[j[l]]), point, nl));
          lane::set(rj_new, l,
                    lane::get(r_j, l) + mc->shift(P, j[l], static_cast<double>(P.id[ii[l]]), point, -nl));
        }
        g.overlap = (ri_new + rj_new) - r;
        g.r_i = ri_new;
        g.r_j = rj_new;
        g.r_eff = ri_new * rj_new / (ri_new + rj_new);
      }
      if (rolling_dashpot(K::rolling(spec))) {
        S i_roll{};
        for (int l = 0; l < W; ++l)
          lane::set(
              i_roll, l,
              rolling_inertia(lane::get(m_i, l), lane::get(r_i, l), lane::get(m_j, l), lane::get(r_j, l)));
        g.i_roll = i_roll;
      } else if constexpr (!K::compiled) {
        g.i_roll = lane::splat<S>(0.0);  // read by no one
      }
      g.omega_i = lane::gather<S>(omega, ii);
      g.omega_j = lane::gather<S>(omega, j);
      if (one_material) {
        mat = material;
      } else {
        const PairMaterial* pm[W];
        for (int l = 0; l < W; ++l)
          pm[l] = &materials(type[ii[l]], type[j[l]]);
        set_materials(mat, pm);
      }
    };
    auto load = [&](int m, V3<S>& v_rel, V3<S>& shear, SlipT<S>& slip, V3<S>& roll)
        __attribute__((always_inline)) {
      v_rel = lane::gather<S>(v, blk_i + m) - lane::gather<S>(v, blk_j + m);
      if (nh > 0) {
        const double* h[W];
        for (int l = 0; l < W; ++l)
          h[l] = pool + static_cast<std::size_t>(slot[blk_k[m + l]]) * nh;
        load_history<K>(spec, h, shear, slip, roll);
      }
    };
    auto store = [&](int m, int nvalid, const GroupOut<S>& r) __attribute__((always_inline)) {
      for (int l = 0; l < nvalid; ++l) {
        const int kk = blk_k[m + l], i = blk_i[m + l], j = blk_j[m + l];
        if (nh > 0) store_history<K>(spec, r, l, pool + static_cast<std::size_t>(slot[kk]) * nh);
        // i's sums in memory, contact after contact: the same additions in
        // the same order as a running sum (no partner of i's row is i)
        const Vec3 force = GroupOut<S>::at(r.force, l);
        f[i] += force;
        torque[i] += GroupOut<S>::at(r.torque_i, l);
        if (newton || j < nlocal) {
          f[j] -= force;
          torque[j] += GroupOut<S>::at(r.torque_j, l);
        }
        if (mc) {
          // this evaluation's contact for the next one: the point in the
          // middle of the geometric overlap, relative to each centre
          const Particles& P = *L.particles;
          const Vec3 d = x[i] - x[j];
          const double rr = d.norm();
          const Vec3 n = d * (1.0 / rr);
          const Vec3 rel_i = MultiContact::offset(radius[i], radius[i] + radius[j] - rr, n);
          const double fn = r.fn[l];
          mc->record(P, i, static_cast<double>(P.id[j]), rel_i, n, fn);
          if (j < nlocal) mc->record(P, j, static_cast<double>(P.id[i]), d + rel_i, -n, fn);
        }
      }
    };
    evaluate_block<K, S>(spec, n, dt, prep, geometry, load, store);
  };

  // a contact that began gets a slot of zeros, one that ended returns its
  // slot (rare, both)
  auto begin_or_end = [&](int k, bool touching) {
    if (touching && slot[k] == kNone)
      history->take(k);
    else if (!touching && slot[k] != kNone)
      history->forget(k);
  };

  // Stage 1 over the list entries as one stream, W at a time (entries of
  // consecutive particles lie one after the other; `owner` names each one's
  // particle), appending the contacts to the block: all entries, or the
  // entries of the near list L.near (ascending) when the caller keeps one.
  const int* const owner = L.owner;
  // The touching lanes' values after the block's (lane::compress: with four
  // lanes and AVX one permutation and one store per array; with W = 4 the
  // group's indices fill the registers, and went to the stack when stored a
  // lane at a time).
  // (near_out: the near list is made on the way, each entry near enough
  // written at the end and the end moved on when it is; no branch)
  int* const near_out = L.near_out;
  const double near_margin = L.near_margin;
  int nnear_out = 0;
  // (entry(q, k, i, j): the q-th entry scanned, its particle and neighbour;
  // slots: the near list's slots, in step with the entries, or null: those
  // of the entries)
  auto stage1 = [&](auto entry, std::int32_t* const slots, int n, auto make_near)
      __attribute__((always_inline)) {
    int nblock = 0;
    int q = 0;
    for (; q + W <= n; q += W) {
      int kk[W], ii[W], jj[W];
      for (int l = 0; l < W; ++l)
        entry(q + l, kk[l], ii[l], jj[l]);
      const V3<S> d = lane::gather<S>(x, ii) - lane::gather<S>(x, jj);
      const S rsum = lane::gather<S>(radius, ii) + lane::gather<S>(radius, jj);
      const S r2 = dot(d, d);
      // the lanes that touch, bit l for lane l
      const int t = lane::bits(lane::mask_and(r2 < rsum * rsum, r2 != 0.0));
      // the touching lanes after the block's contacts, in lane order
      lane::compress<W>(kk, t, blk_k + nblock);
      lane::compress<W>(ii, t, blk_i + nblock);
      nblock += lane::compress<W>(jj, t, blk_j + nblock);
      if constexpr (decltype(make_near)::value) {
        const S reach = rsum + near_margin;
        const int u = lane::bits(r2 < reach * reach);
        nnear_out += lane::compress<W>(kk, u, near_out + nnear_out);
      }
      if (nh > 0) {
        // the lanes that had a contact (a slot: not negative)
        static_assert(kNone < 0);
        const int had = slots ? lane::nonnegative_bits<W>(slots + q) : lane::nonnegative_bits<W>(slot, kk);
        if (had != t) {
          for (int l = 0; l < W; ++l)
            begin_or_end(kk[l], (t >> l) & 1);
          if (slots)
            for (int l = 0; l < W; ++l)
              slots[q + l] = slot[kk[l]];
        }
      }
      if (nblock >= kPairBlock) {
        flush(nblock);
        nblock = 0;
      }
    }
    for (; q < n; ++q) {  // the last entries, one lane's arithmetic
      int k, i, j;
      entry(q, k, i, j);
      const Vec3 d = x[i] - x[j];
      const double rsum = radius[i] + radius[j];
      const double r2 = d.squaredNorm();
      const bool touching = (r2 < rsum * rsum) & (r2 != 0.0);
      blk_k[nblock] = k;
      blk_i[nblock] = i;
      blk_j[nblock] = j;
      nblock += touching;
      if constexpr (decltype(make_near)::value) {
        const double reach = rsum + near_margin;
        near_out[nnear_out] = k;
        nnear_out += r2 < reach * reach;
      }
      if (nh > 0) {
        begin_or_end(k, touching);
        if (slots) slots[q] = slot[k];
      }
    }
    if (nblock > 0) flush(nblock);
  };
  // (the near list's particles from its own arrays, in step with it: through
  // owner[k] and neigh[k] each entry would cost two lines of arrays that
  // hold every list entry, most of them not near)
  auto near_entry = [near = L.near, near_i = L.near_i, near_j = L.near_j](int q, int& k, int& i, int& j) {
    k = near[q];
    i = near_i[q];
    j = near_j[q];
  };
  auto every_entry = [owner, neigh](int q, int& k, int& i, int& j) {
    k = q;
    i = owner[q];
    j = neigh[q];
  };
  if (L.use_near)
    stage1(near_entry, nh > 0 ? L.near_slot : nullptr, L.nnear, std::false_type{});
  else if (near_out)
    stage1(every_entry, nullptr, L.offset[nlocal], std::true_type{});
  else
    stage1(every_entry, nullptr, L.offset[nlocal], std::false_type{});
  return nnear_out;
}

}  // namespace granary
