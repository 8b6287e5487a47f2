#include "pair/pair_granular.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <algorithm>
#include <stdexcept>

#include "contact/contact_kernels.h"
#include "contact/contact_lanes.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "neighbor/neighbor.h"
#include "pair/force.h"
#include "particles/particles.h"

namespace granary {

/// What the lane pair loop (contact::lanes::pair_loop below) reads and writes.
struct PairLoopData {
  int nlocal = 0;
  bool newton = false;
  const int* offset = nullptr;
  const int* neigh = nullptr;
  const Vec3* x = nullptr;
  const Vec3* v = nullptr;
  const Vec3* omega = nullptr;
  Vec3* f = nullptr;
  Vec3* torque = nullptr;
  const double* radius = nullptr;
  const double* rmass = nullptr;
  const double* body_mass = nullptr;  ///< null without clumps
  const int* type = nullptr;
  std::uint8_t* touch = nullptr;
  double* hist = nullptr;
  const int* owner = nullptr;  ///< particle of each list entry
  const MaterialTable* materials = nullptr;
  const contact::ModelSpec* spec = nullptr;
  double dt = 0.0;
};

namespace contact::lanes {

// The pair loop for the kernels of contact_lanes.h, two contacts at a time.
// In blocks of about kBlock contacts:
//  1. all list entries as one stream, W at a time: which touch, without a
//     branch per entry (the history of contacts that ended is cleared); the
//     contacts are appended to the block with their particle;
//  2. for all contacts of the block, W at a time (lanes may hold contacts of
//     different particles): geometry, square roots, coefficients (prepare());
//  3. the rest of the kernel (hertz_history()) and the sums, contact after
//     contact in the list's order, as the scalar loop makes them.
// Long stretches of entries and contacts instead of a particle's few keep
// the loops from ending (a mispredicted branch) at every particle. A
// last group with fewer than W contacts repeats its last contact in the spare
// lanes; their results are not used.
constexpr int kBlock = 64;

template <class Kernel>
void pair_loop(const PairLoopData& L) {
  constexpr int nh = Kernel::history_size;
  static_assert(nh == 3, "lane pair loop: tangential history only");
  const int nlocal = L.nlocal;
  const int* const offset = L.offset;
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
  std::uint8_t* const touch = L.touch;
  double* const hist = L.hist;
  // the block: list position and particle of each contact, first stage's
  // results; fewer than kBlock contacts before the last group of W entries
  constexpr int kCap = kBlock + W;
  int blk_k[kCap], blk_i[kCap];
  Prepared lp[(kCap + W - 1) / W];
  const MaterialTable& materials = *L.materials;
  const ModelSpec spec = *L.spec;
  const double dt = L.dt;
  const bool newton = L.newton;

  auto mass = [&](int a) { return body_mass && body_mass[a] > 0.0 ? body_mass[a] : rmass[a]; };

  // stages 2 and 3 for the n contacts of the block
  auto flush = [&](int n) {
    PairInput in;
    // R* and m* again only for pairs unlike the last group's (exact
    // comparisons: the same operands give the same quotients); radii are
    // positive, so nothing matches at first
    D last_ri = splat(-1.0), last_rj = splat(-1.0), last_mi = splat(-1.0), last_mj = splat(-1.0);
    for (int m = 0; m < n; m += W) {
      int ii[W], j[W];
      for (int l = 0; l < W; ++l) {
        const int c = std::min(m + l, n - 1);
        ii[l] = blk_i[c];
        j[l] = neigh[blk_k[c]];
      }
      in.d = gather(x, ii) - gather(x, j);
      in.r_i = gather(radius, ii);
      in.r_j = gather(radius, j);
      for (int l = 0; l < W; ++l) {
        in.m_i[l] = mass(ii[l]);
        in.m_j[l] = mass(j[l]);
      }
      if (!all((in.r_i == last_ri) & (in.r_j == last_rj) & (in.m_i == last_mi) & (in.m_j == last_mj))) {
        effective_radius_mass(in);
        last_ri = in.r_i;
        last_rj = in.r_j;
        last_mi = in.m_i;
        last_mj = in.m_j;
      }
      for (int l = 0; l < W; ++l) {
        const PairMaterial& mat = materials(type[ii[l]], type[j[l]]);
        in.Y_eff[l] = mat.Y_eff;
        in.G_eff[l] = mat.G_eff;
        in.beta[l] = mat.beta;
        in.dissipative_time[l] = mat.dissipative_time;
        in.friction[l] = mat.friction;
        in.rolling_friction[l] = mat.rolling_friction;
      }
      in.omega_i = gather(omega, ii);
      in.omega_j = gather(omega, j);
      prepare<Kernel::rolling>(spec, in, lp[m / W]);
    }
    PairOutput out;
    for (int m = 0; m < n; m += W) {
      const int nvalid = std::min(W, n - m);
      int kk[W], ii[W], j[W];
      for (int l = 0; l < W; ++l) {
        const int c = std::min(m + l, n - 1);
        kk[l] = blk_k[c];
        ii[l] = blk_i[c];
        j[l] = neigh[kk[l]];
      }
      const V3 v_rel = gather(v, ii) - gather(v, j);
      V3 shear;
      for (int l = 0; l < W; ++l) {
        const double* h = hist + static_cast<std::size_t>(kk[l]) * nh;
        shear.x[l] = h[0];
        shear.y[l] = h[1];
        shear.z[l] = h[2];
      }
      hertz_history<Kernel::rolling, Kernel::limit_force>(lp[m / W], v_rel, gather(omega, ii), dt, shear, out);
      for (int l = 0; l < nvalid; ++l) {
        double* h = hist + static_cast<std::size_t>(kk[l]) * nh;
        h[0] = shear.x[l];
        h[1] = shear.y[l];
        h[2] = shear.z[l];
        touch[kk[l]] = 1;
        // i's sums in memory, contact after contact: the same additions in
        // the same order as a running sum (no partner of i's row is i)
        const Vec3 force = lane(out.force, l);
        f[ii[l]] += force;
        torque[ii[l]] += lane(out.torque_i, l);
        if (newton || j[l] < nlocal) {
          f[j[l]] -= force;
          torque[j[l]] += lane(out.torque_j, l);
        }
      }
    }
  };

  // Stage 1 over all list entries as one stream, W at a time (entries of
  // consecutive particles lie one after the other; `owner` names each one's
  // particle), appending the contacts to the block.
  const int* const owner = L.owner;
  const int nentries = offset[nlocal];
  int nblock = 0;
  int k = 0;
  for (; k + W <= nentries; k += W) {
    int ii[W];
    for (int l = 0; l < W; ++l)
      ii[l] = owner[k + l];
    const V3 d = gather(x, ii) - gather(x, neigh + k);
    const D rsum = gather(radius, ii) + gather(radius, neigh + k);
    const D r2 = dot(d, d);
    const M t = (r2 < rsum * rsum) & (r2 != 0.0);
    bool ended = false;
    for (int l = 0; l < W; ++l) {
      const int tl = static_cast<int>(t[l] & 1);
      blk_k[nblock] = k + l;
      blk_i[nblock] = ii[l];
      nblock += tl;
      ended |= !tl & (touch[k + l] != 0);
    }
    if (ended) {  // a contact that ended: forget its history (rare)
      for (int l = 0; l < W; ++l) {
        if ((t[l] & 1) || touch[k + l] == 0) continue;
        touch[k + l] = 0;
        double* h = hist + static_cast<std::size_t>(k + l) * nh;
        h[0] = h[1] = h[2] = 0.0;
      }
    }
    if (nblock >= kBlock) {
      flush(nblock);
      nblock = 0;
    }
  }
  for (; k < nentries; ++k) {  // the scalar loop's test, same arithmetic
    const int i = owner[k];
    const int j = neigh[k];
    const Vec3 d = x[i] - x[j];
    const double rsum = radius[i] + radius[j];
    const double r2 = d.squaredNorm();
    const bool touching = (r2 < rsum * rsum) & (r2 != 0.0);
    blk_k[nblock] = k;
    blk_i[nblock] = i;
    nblock += touching;
    if (!touching & (touch[k] != 0)) {
      touch[k] = 0;
      double* h = hist + static_cast<std::size_t>(k) * nh;
      h[0] = h[1] = h[2] = 0.0;
    }
  }
  if (nblock > 0) flush(nblock);
}

}  // namespace contact::lanes

namespace {
contact::ModelSpec parse_spec(const std::string& style, const Args& args) {
  std::vector<std::string> words;
  if (style == "hertz/rolling") {
    // Granary's name: Hertz, tangential history and cdt rolling unless overridden.
    words = {"model", "hertz", "tangential", "history", "rolling_friction", "cdt"};
    for (std::size_t k = 0; k + 1 < args.size(); k += 2) {
      const std::string slot = args[k] == "rolling" ? "rolling_friction" : args[k];
      bool replaced = false;
      for (std::size_t w = 0; w + 1 < words.size(); w += 2) {
        if (words[w] == slot) {
          words[w + 1] = args[k + 1];
          replaced = true;
        }
      }
      if (!replaced) {
        words.push_back(slot);
        words.push_back(args[k + 1]);
      }
    }
    if (args.size() % 2)
      throw InputError("pair_style hertz/rolling takes keyword/value pairs; '" + args.back() +
                       "' has no value");
  } else {
    words = args;
  }
  std::size_t pos = 0;
  contact::ModelSpec spec;
  try {
    spec = contact::parse_model_words(words, pos);
  } catch (const std::invalid_argument& e) {
    throw InputError("pair_style " + style + ": " + e.what());
  }
  if (pos != words.size()) {
    throw InputError("pair_style " + style + ": unexpected word '" + words[pos] +
                     "'; expected model, tangential, rolling_friction, cohesion, damping or limitForce");
  }
  return spec;
}
}  // namespace

PairGranular::PairGranular(Engine& engine, const Args& args, const std::string& style_name)
    : Pair(engine, args) {
  style = style_name;
  spec_ = parse_spec(style_name, args);
}

void PairGranular::coeff(const Args& args) {
  require_args(args, 2, 2, "pair_coeff * *");
  int lo, hi;
  const int n = engine_.particles->ntypes;
  for (int k = 0; k < 2; ++k) {
    parse_type_range(args[k], n, lo, hi);
    if (lo != 1 || hi != n) {
      throw InputError(
          "granular pair styles take their parameters from fix property/global for all "
          "types at once; use pair_coeff * *");
    }
  }
  coeff_set_ = true;
}

void PairGranular::init() {
  if (!coeff_set_) throw InputError("pair style " + style + " needs 'pair_coeff * *' before run");
  materials_.build(engine_, spec_, "pair_style " + style);
  std::vector<double> signs(history_size());
  if (!signs.empty()) history_swap_signs(signs.data());
  if (history_.nvalues() != history_size()) history_.configure(history_size(), signs);
  take_restart_history();

  // A timestep longer than the Rayleigh time cannot resolve a contact.
  const double tr = min_rayleigh_time(engine_, materials_);
  const double dt = engine_.update->dt;
  if (tr > 0 && std::isfinite(tr) && tr < 1e300 && dt > tr) {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "timestep %g s is longer than the Rayleigh time %g s of the stiffest particle; "
                  "contacts cannot be resolved. Use a timestep below %g s (20%% of the Rayleigh time) "
                  "or a smaller Young's modulus",
                  dt, tr, 0.2 * tr);
    throw InputError(buf);
  }
}

// Contact history read by read_restart waits in Force until the pair style
// that uses it initialises; its layout must match this model's.
void PairGranular::take_restart_history() {
  Force& force = *engine_.force;
  if (force.restart_history.size() < 2) return;
  const int nvalues = static_cast<int>(force.restart_history[1]);
  if (nvalues == history_size()) {
    history_.unpack_all(force.restart_history);
  } else if (force.restart_history[0] > 0) {
    engine_.logger->warning("the restart file's contact history has " + std::to_string(nvalues) +
                            " values per contact but pair_style " + style + " " + join(args_) + " uses " +
                            std::to_string(history_size()) + "; contacts start without history");
  }
  if (!force.restart_pair_style.empty() && force.restart_pair_style != style + " " + join(args_)) {
    engine_.logger->warning("pair style differs from the restart file's (" + force.restart_pair_style + ")");
  }
  force.restart_history.clear();
}

// Kernels that contact_lanes.h provides (Hertz, tangential history, cdt or no
// rolling) run in lane_loop(): the three passes of scalar_loop() with whole
// kernels two contacts at a time. The others run in scalar_loop().
template <class Kernel>
void PairGranular::loop() {
  // contact history: one slot per neighbour-list entry
  constexpr int nh = Kernel::history_size;
  const std::size_t nlist = engine_.neighbor->neigh.size();
  if (nh > 0 && history_.touch_.size() != nlist) {
    history_.touch_.assign(nlist, 0);
    history_.values_.assign(nlist * nh, 0.0);
  }
  if constexpr (contact::lanes::supported<Kernel>())
    lane_loop<Kernel>();
  else
    scalar_loop<Kernel>();
}

// The hot loop reads particle data through local pointers: stores to the
// one-byte touch flags may alias anything, and members read through
// references would be reloaded after each of them.
//
// Three passes per particle. The first runs over all its list entries, finds
// those in contact and stores their positions without a branch (whether a
// listed pair touches is close to a coin toss in a dense bed, and a
// mispredicted branch per entry costs more than the distance test itself);
// it also clears the history of contacts that just ended. The second computes
// the contacts' geometry and the square roots and divisions that do not
// depend on the history (Kernel::roots): in one kernel call they form a long
// chain of dependent slow operations, while across contacts they are
// independent and the processor overlaps them. The third runs the rest of
// the kernel. The operations are those of a single kernel call, in the same
// order, so the results are the same to the last bit.
template <class Kernel>
void PairGranular::scalar_loop() {
  Particles& p = *engine_.particles;
  const Neighbor& list = *engine_.neighbor;
  const int nlocal = p.nlocal;
  const bool newton = engine_.force->newton_pair;
  constexpr int nh = Kernel::history_size;
  double dummy[6] = {0, 0, 0, 0, 0, 0};
  // sub-spheres of clumps use their body's mass (field filled by fix multisphere)
  const int body_mass_field = p.find_field("body_mass");
  const double* const body_mass = body_mass_field >= 0 ? p.extras[body_mass_field].data.data() : nullptr;
  const Vec3* const x = p.x.data();
  const Vec3* const v = p.v.data();
  const Vec3* const omega = p.omega.data();
  Vec3* const f = p.f.data();
  Vec3* const torque = p.torque.data();
  const double* const radius = p.radius.data();
  const double* const rmass = p.rmass.data();
  const int* const type = p.type.data();
  const int* const offset = list.offset.data();
  const int* const neigh = list.neigh.data();
  std::uint8_t* const touch = history_.touch_.data();
  double* const hist = history_.values_.data();
  const contact::ModelSpec spec = spec_;
  const MaterialTable& materials = materials_;
  int maxrow = 0;
  for (int i = 0; i < nlocal; ++i)
    maxrow = std::max(maxrow, offset[i + 1] - offset[i]);
  if (static_cast<int>(contacts_.size()) < maxrow) contacts_.resize(maxrow);
  if (static_cast<int>(prepared_.size()) < maxrow) prepared_.resize(maxrow);
  int* const in_contact = contacts_.data();
  Prepared* const prep = prepared_.data();
  contact::ContactState c;
  contact::ContactResult res;
  c.dt = engine_.update->history_dt();
  for (int i = 0; i < nlocal; ++i) {
    const Vec3 xi = x[i];
    const double ri = radius[i];
    const int ti = type[i];
    const int kbegin = offset[i], kend = offset[i + 1];
    int ncontact = 0;
    for (int k = kbegin; k < kend; ++k) {
      const int j = neigh[k];
      const Vec3 d = xi - x[j];
      const double rsum = ri + radius[j];
      const double r2 = d.squaredNorm();
      const bool touching = (r2 < rsum * rsum) & (r2 != 0.0);
      in_contact[ncontact] = k;
      prep[ncontact].r2 = r2;
      ncontact += touching;
      if constexpr (nh > 0) {
        // a contact that ended: forget its history (rare, so well predicted)
        if (!touching & (touch[k] != 0)) {
          touch[k] = 0;
          double* h = hist + static_cast<std::size_t>(k) * nh;
          for (int q = 0; q < nh; ++q)
            h[q] = 0.0;
        }
      }
    }
    // two contacts at a time, one per lane of packed operations (an odd last
    // contact is computed twice)
    for (int m = 0; m < ncontact; m += 2) {
      const int m1 = m + 1 < ncontact ? m + 1 : m;
      const int j0 = neigh[in_contact[m]], j1 = neigh[in_contact[m1]];
      const contact::PairMaterial& mat0 = materials(ti, type[j0]);
      const contact::PairMaterial& mat1 = materials(ti, type[j1]);
      using A2 = Eigen::Array2d;
      const A2 rj(radius[j0], radius[j1]);
      const A2 rsum = ri + rj;
      const A2 r = A2(prep[m].r2, prep[m1].r2).sqrt();
      // 1/r, then n = d * (1/r), not d / r: the same rounding as LIGGGHTS
      // (round-off spins feed the cdt rolling torque, so the last bit matters)
      const A2 inv_r = 1.0 / r;
      const A2 overlap = rsum - r;
      const A2 r_eff = ri * rj / rsum;
      double mi = rmass[i], mj0 = rmass[j0], mj1 = rmass[j1];
      if (body_mass) {
        if (body_mass[i] > 0.0) mi = body_mass[i];
        if (body_mass[j0] > 0.0) mj0 = body_mass[j0];
        if (body_mass[j1] > 0.0) mj1 = body_mass[j1];
      }
      const A2 mj(mj0, mj1);
      const A2 m_eff = mi * mj / (mi + mj);
      const Vec3 w0 = omega[i] - omega[j0], w1 = omega[i] - omega[j1];
      A2 sqrt_rd = A2::Zero(), root_n = A2::Zero(), root_t = A2::Zero(), spin = A2::Zero();
      contact::detail::contact_roots_lanes<Kernel::normal, Kernel::rolling, A2>(
          spec, r_eff, overlap, m_eff, A2(mat0.Y_eff, mat1.Y_eff), A2(mat0.G_eff, mat1.G_eff),
          A2(w0[0], w1[0]), A2(w0[1], w1[1]), A2(w0[2], w1[2]), sqrt_rd, root_n, root_t, spin);
      Prepared* const out[2] = {&prep[m], &prep[m1]};
      for (int l = 0; l < 2; ++l) {
        Prepared& q = *out[l];
        q.inv_r = inv_r[l];
        q.overlap = overlap[l];
        q.r_eff = r_eff[l];
        q.m_eff = m_eff[l];
        q.roots.sqrt_rd = sqrt_rd[l];
        q.roots.root_n = root_n[l];
        q.roots.root_t = root_t[l];
        q.roots.spin = spin[l];
      }
    }
    // the force and torque on i are summed in registers (j != i, so the
    // stores to j cannot touch them), in the order of the list as before
    Vec3 fi = f[i], ti_sum = torque[i];
    for (int m = 0; m < ncontact; ++m) {
      const Prepared& q = prep[m];
      const int k = in_contact[m];
      const int j = neigh[k];
      const Vec3 d = xi - x[j];
      double* h = nh > 0 ? hist + static_cast<std::size_t>(k) * nh : dummy;
      c.n = d * q.inv_r;
      c.overlap = q.overlap;
      c.r_i = ri;
      c.r_j = radius[j];
      c.r_eff = q.r_eff;
      c.m_eff = q.m_eff;
      c.v_rel = v[i] - v[j];
      c.omega_i = omega[i];
      c.omega_j = omega[j];
      Kernel::evaluate_prepared(spec, c, materials(ti, type[j]), q.roots, h, res);
      if constexpr (nh > 0) touch[k] = 1;
      fi += res.force;
      ti_sum += res.torque_i;
      if (newton || j < nlocal) {
        f[j] -= res.force;
        torque[j] += res.torque_j;
      }
    }
    f[i] = fi;
    torque[i] = ti_sum;
  }
}

// The kernels of contact_lanes.h, two contacts at a time: same results as
// the scalar loop below.
template <class Kernel>
void PairGranular::lane_loop() {
  Particles& p = *engine_.particles;
  const Neighbor& list = *engine_.neighbor;
  PairLoopData L;
  L.nlocal = p.nlocal;
  L.newton = engine_.force->newton_pair;
  L.offset = list.offset.data();
  L.neigh = list.neigh.data();
  L.x = p.x.data();
  L.v = p.v.data();
  L.omega = p.omega.data();
  L.f = p.f.data();
  L.torque = p.torque.data();
  L.radius = p.radius.data();
  L.rmass = p.rmass.data();
  const int body_mass_field = p.find_field("body_mass");
  L.body_mass = body_mass_field >= 0 ? p.extras[body_mass_field].data.data() : nullptr;
  L.type = p.type.data();
  L.touch = history_.touch_.data();
  L.hist = history_.values_.data();
  L.materials = &materials_;
  L.spec = &spec_;
  L.dt = engine_.update->history_dt();
  // the particle of each list entry, for stage 1's single stream
  if (owner_build_ != list.nbuilds || owner_.size() != list.neigh.size()) {
    owner_.resize(list.neigh.size());
    for (int i = 0; i < p.nlocal; ++i)
      std::fill(owner_.begin() + L.offset[i], owner_.begin() + L.offset[i + 1], i);
    owner_build_ = list.nbuilds;
  }
  L.owner = owner_.data();
  contact::lanes::pair_loop<Kernel>(L);
}

void PairGranular::compute() {
  contact::dispatch_model(spec_, [this](auto kernel) { this->loop<decltype(kernel)>(); });
}

GRANARY_PAIR_STYLE("gran", PairGran);
GRANARY_PAIR_STYLE("hertz/rolling", PairHertzRolling);

}  // namespace granary
