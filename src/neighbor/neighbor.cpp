#include "neighbor/neighbor.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "comm/comm.h"
#include "contact/lane.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/growth.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "core/force.h"
#include "particles/particles.h"

namespace granary {

Neighbor::Neighbor(Engine& engine) : engine_(engine) {}

void Neighbor::neighbor_command(const Args& args) {
  require_args(args, 2, 2, "neighbor SKIN bin|nsq");
  skin = parse_double(args[0], "neighbor skin");
  if (skin < 0) throw InputError("neighbor skin must be >= 0");
  if (args[1] != "bin" && args[1] != "nsq" && args[1] != "multi") {
    throw InputError("neighbor style must be bin (or nsq), got '" + args[1] + "'");
  }
}

void Neighbor::modify_command(const Args& args) {
  if (args.empty()) throw InputError("usage: neigh_modify keyword value ...");
  const int ntypes = engine_.particles->ntypes;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& w = args[k];
    auto value = [&](const char* what) -> const std::string& {
      if (k + 1 >= args.size()) throw InputError(std::string("neigh_modify ") + what + " needs a value");
      return args[++k];
    };
    if (w == "every")
      every = static_cast<int>(parse_int(value("every"), "every"));
    else if (w == "delay")
      delay = static_cast<int>(parse_int(value("delay"), "delay"));
    else if (w == "check")
      check = parse_bool(value("check"), "check");
    else if (w == "once")
      once = parse_bool(value("once"), "once");
    else if (w == "page" || w == "one" || w == "binsize" || w == "contact_distance_factor")
      value(w.c_str());
    else if (w == "exclude") {
      const std::string& kind = value("exclude");
      if (kind == "none") {
        exclude_types_.clear();
        exclude_groups_.clear();
      } else if (kind == "type") {
        if (k + 2 >= args.size()) throw InputError("neigh_modify exclude type needs two types");
        int lo1, hi1, lo2, hi2;
        parse_type_range(args[k + 1], ntypes, lo1, hi1);
        parse_type_range(args[k + 2], ntypes, lo2, hi2);
        for (int a = lo1; a <= hi1; ++a)
          for (int b = lo2; b <= hi2; ++b)
            exclude_types_.emplace_back(a, b);
        k += 2;
      } else if (kind == "group") {
        if (k + 2 >= args.size()) throw InputError("neigh_modify exclude group needs two groups");
        const int g1 = engine_.groups->find_or_error(args[k + 1], "neigh_modify exclude");
        const int g2 = engine_.groups->find_or_error(args[k + 2], "neigh_modify exclude");
        exclude_groups_.emplace_back(engine_.groups->bitmask(g1), engine_.groups->bitmask(g2));
        k += 2;
      } else if (kind == "molecule" || kind == "molecule/intra") {
        value("exclude molecule");
        exclude_body_ = true;  // always on: sub-spheres of one clump never interact
      } else {
        throw InputError("neigh_modify exclude takes type, group, molecule/intra or none, got '" + kind +
                         "'");
      }
    } else {
      throw InputError("unknown neigh_modify keyword '" + w +
                       "'; expected every, delay, check, once or exclude");
    }
  }
  if (every < 1 || delay < 0) throw InputError("neigh_modify needs every >= 1 and delay >= 0");
}

void Neighbor::init() {
  rmax = engine_.particles->max_radius(engine_.world);
  cutneighmax = cutoff_for(rmax);
}

bool Neighbor::excluded(int i, int j) const {
  const Particles& p = *engine_.particles;
  if (exclude_body_ && p.body[i] >= 0 && p.body[i] == p.body[j]) return true;
  for (const auto& t : exclude_types_) {
    if ((p.type[i] == t.first && p.type[j] == t.second) || (p.type[i] == t.second && p.type[j] == t.first))
      return true;
  }
  for (const auto& g : exclude_groups_) {
    if (((p.mask[i] & g.first) && (p.mask[j] & g.second)) ||
        ((p.mask[i] & g.second) && (p.mask[j] & g.first)))
      return true;
  }
  return false;
}

bool Neighbor::decide(int* carry) {
  watch_checked_ = false;
  const int mine = carry ? *carry : 0;
  if (carry) *carry = -1;
  if (force_rebuild) {
    force_rebuild = false;
    return true;
  }
  if (once) return false;
  // Spatial sorting happens at fixed step multiples, on a rebuild forced there.
  if (sort_every > 0 && engine_.update->ntimestep % sort_every == 0) return true;
  if (ago < delay || ago % every != 0) return false;
  if (!check) return true;
  const Particles& p = *engine_.particles;
  const int n = std::min<int>(p.nlocal, static_cast<int>(xhold_.size()));
  const Vec3* const x = p.x.data();
  // local[0]: moved beyond half the skin since the build; local[1]: beyond
  // the watch's limit since its reference (watch_ready_ is alike on every
  // rank: set by the collective builds)
  // local[2]: the caller's value carried along
  int local[3] = {n != p.nlocal, 0, mine};
  if (!local[0]) {
    // |x - xhold| <= |x - watch_x| + |watch_x - xhold|: below half the skin
    // (with room for rounding) no particle can have moved beyond it
    const double w2 = watch_ready_ ? max_displacement2(x, watch_x_.data(), n) : 0.0;
    local[1] = w2 > watch_limit2_;
    if (!watch_ready_ || std::sqrt(w2) + watch_hold_ > 0.5 * skin * (1.0 - 1e-9))
      local[0] = moved_beyond(x, xhold_.data(), n, 0.25 * skin * skin);
  }
  int any[3] = {0, 0, 0};
  MPI_Allreduce(local, any, 3, MPI_INT, MPI_MAX, engine_.world);
  if (carry) *carry = any[2];
  if (any[0]) return true;  // (the build takes the watch's positions anew)
  watch_checked_ = watch_ready_;
  if (any[1]) {
    watch_x_.assign(x, x + n);
    watch_hold_ = std::sqrt(max_displacement2(x, xhold_.data(), n));
    ++watch_epoch_;
  }
  return false;
}

bool Neighbor::moved_beyond(const Vec3* x, const Vec3* x0, int n, double limit2) {
  for (int b = 0; b < n; b += 1024) {
    const int e = std::min(n, b + 1024);
    int over = 0;
    for (int i = b; i < e; ++i)
      over |= (x[i] - x0[i]).squaredNorm() > limit2;
    if (over) return true;
  }
  return false;
}

double Neighbor::max_displacement2(const Vec3* x, const Vec3* x0, int n) {
  // four running maxima: no chain of dependent comparisons
  double m[4] = {0.0, 0.0, 0.0, 0.0};
  int i = 0;
  for (; i + 3 < n; i += 4)
    for (int q = 0; q < 4; ++q)
      m[q] = std::max(m[q], (x[i + q] - x0[i + q]).squaredNorm());
  for (; i < n; ++i)
    m[0] = std::max(m[0], (x[i] - x0[i]).squaredNorm());
  return std::max(std::max(m[0], m[1]), std::max(m[2], m[3]));
}

bool Neighbor::same_values(const double* a, const double* b, int n) {
  for (int s = 0; s < n; s += 1024) {
    const int e = std::min(n, s + 1024);
    int differ = 0;
    for (int i = s; i < e; ++i)
      differ |= a[i] != b[i];
    if (differ) return false;
  }
  return true;
}

void Neighbor::sort_particles(std::int64_t step) {
  if (sort_every <= 0 || step % sort_every != 0) return;
  Particles& p = *engine_.particles;
  const Domain& dom = *engine_.domain;
  const int n = p.nlocal;
  if (n < 2) return;
  const double bin = sort_binsize > 0 ? sort_binsize : std::max(0.5 * cutneighmax, 1e-12);
  int nb[3];
  for (int d = 0; d < 3; ++d)
    nb[d] = std::clamp(static_cast<int>((dom.subhi[d] - dom.sublo[d]) / bin), 1, 1 << 10);
  std::vector<std::int64_t> key(n);
  for (int i = 0; i < n; ++i) {
    std::int64_t c[3];
    for (int d = 0; d < 3; ++d) {
      const double f = (p.x[i][d] - dom.sublo[d]) / (dom.subhi[d] - dom.sublo[d]);
      c[d] = std::clamp(static_cast<int>(f * nb[d]), 0, nb[d] - 1);
    }
    key[i] = (c[2] * nb[1] + c[1]) * nb[0] + c[0];
  }
  // The sub-spheres of a clump stay together, in id order, in the bin of the
  // first of them in the current order: fix multisphere places them and sums
  // their forces body by body, reading each body's state once.
  // Free spheres after all sub-spheres, each part in bin order: the fixes that
  // integrate only one kind (nve/sphere the free spheres, multisphere the
  // sub-spheres) then stream through their own particles instead of picking
  // them out of lines shared with the other kind.
  const std::int64_t nbins = static_cast<std::int64_t>(nb[0]) * nb[1] * nb[2];
  std::unordered_map<tagint, std::int64_t> body_key;
  for (int i = 0; i < n; ++i)
    key[i] = p.body[i] >= 0 ? body_key.emplace(p.body[i], key[i]).first->second : key[i] + nbins;
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i)
    order[i] = i;
  const tagint* const body = p.body.data();
  const tagint* const id = p.id.data();
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (key[a] != key[b]) return key[a] < key[b];
    if (body[a] != body[b]) return body[a] < body[b];
    return body[a] >= 0 ? id[a] < id[b] : a < b;
  });
  p.permute(order);
}

void Neighbor::build() {
  const Particles& p = *engine_.particles;
  const Domain& dom = *engine_.domain;
  const int nlocal = p.nlocal, nall = p.size();
  const bool newton = engine_.force->newton_pair;
  xhold_.assign(p.x.begin(), p.x.begin() + nlocal);
  ago = 0;
  ++nbuilds;
  watch_ready_ = watch_limit2_ > 0.0;
  if (watch_ready_) watch_x_ = xhold_;
  watch_hold_ = 0.0;
  watch_checked_ = false;
  ++watch_epoch_;

  offset.assign(nlocal + 1, 0);
  neigh.clear();
  if (nlocal == 0) return;

  // Bins cover the subdomain plus the ghost shell; bin size >= the largest cutoff.
  const double cut = std::max(cutneighmax, 1e-12);
  const double ghost = engine_.comm->cutghost;
  Vec3 lo, hi;
  int nbin[3];
  double binsize[3];
  // Bins at least one cutoff wide; a sparse system in a large box gets larger
  // bins so that there are never many more bins than particles.
  const double max_bins = 8.0 * nall + 1000.0;
  double scale = 1.0;
  for (int pass = 0; pass < 64; ++pass) {
    double total = 1.0;
    for (int d = 0; d < 3; ++d) {
      lo[d] = dom.sublo[d] - ghost - 1e-12;
      hi[d] = dom.subhi[d] + ghost + 1e-12;
      nbin[d] = std::clamp(static_cast<int>((hi[d] - lo[d]) / (cut * scale)), 1, 1 << 20);
      binsize[d] = (hi[d] - lo[d]) / nbin[d];
      total *= nbin[d];
    }
    if (total <= max_bins) break;
    scale *= 1.5;
  }
  auto coord = [&](const Vec3& x, int d) {
    int c = static_cast<int>((x[d] - lo[d]) / binsize[d]);
    return std::clamp(c, 0, nbin[d] - 1);
  };
  const std::size_t nbins = static_cast<std::size_t>(nbin[0]) * nbin[1] * nbin[2];
  const Vec3* const x = p.x.data();
  const double* const radius = p.radius.data();
  const tagint* const id = p.id.data();
  const tagint* const body = p.body.data();
  // counting sort of all particles (owned, then ghosts) into the bins; a
  // stable pass in index order keeps every bin in ascending index order
  bin_of_.resize(nall);
  binstart_.assign(nbins + 1, 0);
  bool bodies = false;  // any sub-sphere of a clump, whose own body is left out
  double rbin = 0.0;    // the largest radius in the bins
  for (int i = 0; i < nall; ++i) {
    const int b = (coord(x[i], 2) * nbin[1] + coord(x[i], 1)) * nbin[0] + coord(x[i], 0);
    bin_of_[i] = b;
    ++binstart_[b + 1];
    bodies |= body[i] >= 0;
    rbin = std::max(rbin, radius[i]);
  }
  bodies = bodies && exclude_body_;
  std::size_t occupied = 0;
  for (std::size_t b = 0; b < nbins; ++b) {
    occupied += binstart_[b + 1] > 0;
    binstart_[b + 1] += binstart_[b];
  }
  // bins left out by distance (below) from the next build on where the bins
  // are crowded (clumps of many overlapping sub-spheres): with a few
  // particles per bin the test costs about what it saves
  const bool prune = prune_bins_;
  pruned_bins_ = prune;
  prune_bins_ = occupied > 0 && static_cast<double>(nall) / static_cast<double>(occupied) > kCrowdedBin;
  // the candidates are tested W at a time (the lanes of contact::lane::Wide)
  using S = contact::lane::Wide;
  constexpr int W = contact::lane::width<S>();
  const std::size_t padded = static_cast<std::size_t>(nall) + (W - 1);
  binpart_.resize(padded);
  for (auto& c : binx_)
    c.resize(padded);
  binr_.resize(padded);
  // the key: the body's id for a sub-sphere, -1 - index for a free sphere
  auto key = [body](int i) { return body[i] >= 0 ? body[i] : -1 - static_cast<tagint>(i); };
  if (bodies) binkey_.resize(padded);
  {
    std::vector<int> fill(binstart_.begin(), binstart_.end() - 1);
    for (int i = 0; i < nall; ++i) {
      const int k = fill[bin_of_[i]]++;
      binpart_[k] = i;
      for (int d = 0; d < 3; ++d)
        binx_[d][k] = x[i][d];
      binr_[k] = radius[i];
      if (bodies) binkey_[k] = key(i);
    }
  }
  const int* const bstart = binstart_.data();
  const int* const bpart = binpart_.data();
  const double* const bx = binx_[0].data();
  const double* const by = binx_[1].data();
  const double* const bz = binx_[2].data();
  const double* const br = binr_.data();
  const tagint* const bkey = bodies ? binkey_.data() : nullptr;
  // per bin: where its particles of index above the current i begin
  bincursor_.assign(binstart_.begin(), binstart_.end() - 1);
  int* const cursor = bincursor_.data();
  const bool other_exclusions = !exclude_types_.empty() || !exclude_groups_.empty();
  const double sk = skin;
  const double rf = range_factor;

  // Candidates are appended without a branch (whether one is within the
  // cutoff is unpredictable): each is written at the end and the end moves
  // on when it is near and, with clumps, of another body. The other
  // exclusions, possible only with ghosts or neigh_modify exclude, are
  // filtered afterwards.
  const bool filter = nall > nlocal || other_exclusions;
  // room for 8 partners per particle to start with (the old list is not kept)
  if (neigh.size() < static_cast<std::size_t>(nlocal) * 8)
    assign_fresh(neigh, static_cast<std::size_t>(nlocal) * 8, 0);
  std::size_t end = 0;
  // a margin for the rounding of the bin edges and of a particle's bin
  const double margin = 1e-9 * cut;
  for (int i = 0; i < nlocal; ++i) {
    offset[i] = static_cast<int>(end);
    const int cx = coord(x[i], 0), cy = coord(x[i], 1), cz = coord(x[i], 2);
    const double ri = radius[i];
    const Vec3 xi = x[i];
    const tagint ki = bodies ? key(i) : 0;
    // No partner of i is further than reach; a neighbouring bin no point of
    // which is within reach is left out (when pruning). gap[d][0] and
    // gap[d][1]: the squared distances from x_i to the bins below and above
    // its own in direction d (lower bounds: less the margin; 0 outside the
    // bins, and 0 when not pruning).
    const double reach = (ri + rbin) * rf + sk, reach2 = reach * reach;
    const int cell[3] = {cx, cy, cz};
    double gap[3][2] = {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}};
    for (int d = 0; d < 3 && prune; ++d) {
      const double edge = lo[d] + cell[d] * binsize[d];
      const double below = std::max(xi[d] - edge - margin, 0.0);
      const double above = std::max(edge + binsize[d] - xi[d] - margin, 0.0);
      gap[d][0] = below * below;
      gap[d][1] = above * above;
    }
    auto gap2 = [&](int d, int delta) { return delta == 0 ? 0.0 : gap[d][delta > 0]; };
    // the candidates k of [kbeg, kend) within the cutoff (and of another
    // body), W at a time: the lanes within (past kend: none) placed at the
    // end and the end moved on by their number; no branch on a candidate.
    // Per lane the operations of (x_i - x_k).squaredNorm() < rc * rc in
    // Eigen's order, so the list is the one a candidate at a time gives.
    const S sx = contact::lane::splat<S>(xi[0]), sy = contact::lane::splat<S>(xi[1]),
            sz = contact::lane::splat<S>(xi[2]), sri = contact::lane::splat<S>(ri);
    const auto ski = contact::lane::splat_int<S>(ki);
    // the candidates k .. k + W - 1 of the lanes set in `lanes`
    auto group = [&](int* out, int k, int lanes) __attribute__((always_inline)) {
      using contact::lane::load;
      const S dx = sx - load<S>(bx + k), dy = sy - load<S>(by + k), dz = sz - load<S>(bz + k);
      const S d2 = (dx * dx + dy * dy) + dz * dz;
      const S rc = (sri + load<S>(br + k)) * rf + sk;
      int t = contact::lane::bits(d2 < rc * rc) & lanes;
      if (bkey) t &= contact::lane::differ_bits<S>(bkey + k, ski);
      end += contact::lane::compress<W>(bpart + k, t, out + end);
    };
    auto scan = [&](int kbeg, int kend) __attribute__((always_inline)) {
      if (neigh.size() < end + static_cast<std::size_t>(kend - kbeg) + W)
        grow_keep(neigh,
                  std::max(neigh.size() + neigh.size() / 4, end + static_cast<std::size_t>(kend - kbeg) + W));
      int* const out = neigh.data();
      int k = kbeg;
      for (; k + W <= kend; k += W)
        group(out, k, (1 << W) - 1);
      if (k < kend) group(out, k, (1 << (kend - k)) - 1);  // the last lanes past kend left out
    };
    for (int dz = -1; dz <= 1; ++dz) {
      const int z = cz + dz;
      if (z < 0 || z >= nbin[2]) continue;
      const double gz = gap2(2, dz);
      if (gz > reach2) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        const int y = cy + dy;
        if (y < 0 || y >= nbin[1]) continue;
        const double gyz = gz + gap2(1, dy);
        if (gyz > reach2) continue;
        const int row = (z * nbin[1] + y) * nbin[0];
        const int x0 = std::max(gyz + gap[0][0] <= reach2 ? cx - 1 : cx, 0);
        const int x1 = std::min(gyz + gap[0][1] <= reach2 ? cx + 1 : cx, nbin[0] - 1);
        // Each pair once: only partners of higher index (every ghost's index
        // is above every owned one). A bin holds its particles in ascending
        // index order, so its partners are a tail of it, which starts at or
        // after where it started for the last particle (cursor: each bin's
        // entries are passed over once in the whole build; after a spatial
        // sort, the bins below i hold no partner). The bins x0..x1 of a row
        // lie one after the other: the tails that join up are scanned as one
        // range.
        int kbeg = -1, kend = -1;  // the range gathered so far: none
        for (int b = row + x0; b <= row + x1; ++b) {
          const int te = bstart[b + 1];
          int tb = cursor[b];
          while (tb < te && bpart[tb] <= i)
            ++tb;
          cursor[b] = tb;
          if (tb == te) continue;  // no partner in bin b
          if (tb == kend) {        // joins the range
            kend = te;
            continue;
          }
          if (kbeg < kend) scan(kbeg, kend);
          kbeg = tb;
          kend = te;
        }
        if (kbeg < kend) scan(kbeg, kend);
      }
    }
    if (filter) {
      std::size_t kept = offset[i];
      for (std::size_t a = offset[i]; a < end; ++a) {
        const int j = neigh[a];
        if (j >= nlocal && (id[j] == id[i] || (newton && id[j] < id[i]))) continue;
        if (other_exclusions && excluded(i, j)) continue;
        neigh[kept++] = j;
      }
      end = kept;
    }
    // Neighbours in id order: each particle's forces are then summed in an
    // order that does not depend on when the list was built (restarts
    // continue bit for bit).
    int* const lst = neigh.data() + offset[i];
    const int m = static_cast<int>(end) - offset[i];
    for (int a = 1; a < m; ++a) {  // short lists: insertion sort by (id, index)
      const int v = lst[a];
      const tagint key = id[v];
      int b = a - 1;
      while (b >= 0 && (id[lst[b]] > key || (id[lst[b]] == key && lst[b] > v))) {
        lst[b + 1] = lst[b];
        --b;
      }
      lst[b + 1] = v;
    }
  }
  neigh.resize(end);
  offset[nlocal] = static_cast<int>(end);
}

void cmd_neighbor(Engine& e, const Args& a) {
  e.neighbor->neighbor_command(a);
}
void cmd_neigh_modify(Engine& e, const Args& a) {
  e.neighbor->modify_command(a);
}
GRANARY_COMMAND("neighbor", cmd_neighbor);
GRANARY_COMMAND("neigh_modify", cmd_neigh_modify);

}  // namespace granary
