// compute ID group region/phi REGION [type T1 T2 ...] [clump mc|scale]
//         [samples N] [seed S]
//
// Solid volume fraction of the group's particles in a block region:
//   scalar  phi   = sum_i V(particle i inside the block) / V_block
//   vector  phi_t = the same restricted to atom type t (types 1..ntypes, or
//                   the listed types in the listed order)
// Free spheres contribute the exact volume of the sphere-box intersection
// (sphere_box_volume). A clump (a body of fix multisphere) contributes the
// in-box volume of the union of its sub-spheres, once: its solid volume when
// it lies wholly inside the block, zero when wholly outside; when the block
// cuts it, by default (clump mc) the body volume times the fraction of N
// points drawn uniformly in the union (fixed seed per body) that lie in the
// block, or (clump scale) the sum of the sub-spheres' exact in-box volumes
// scaled by body volume / sum of sub-sphere volumes. Periodic images of the
// particles are taken into account. Collective.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "compute/compute.h"
#include "geometry/sphere_box_volume.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "particles/clumps.h"
#include "core/modify.h"
#include "particles/bodies.h"
#include "particles/particles.h"

namespace granary {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// splitmix64: a small, portable generator (identical streams everywhere).
struct SplitMix {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return (next() >> 11) * (1.0 / 9007199254740992.0); }  // [0, 1)
};

class ComputeRegionPhi : public Compute {
 public:
  ComputeRegionPhi(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage =
        "compute ID group-ID region/phi REGION [type T1 T2 ...] [clump mc|scale] [samples N] [seed S]";
    if (args.size() < 4) throw InputError("usage: " + usage);
    region_id_ = args[3];
    block();  // checks the region now
    const int ntypes = engine.particles->ntypes;
    if (ntypes <= 0)
      throw InputError("compute " + id + " region/phi needs the simulation box; use create_box first");
    std::size_t k = 4;
    while (k < args.size()) {
      const std::string& key = args[k];
      if (key == "type") {
        ++k;
        while (k < args.size() && args[k] != "clump" && args[k] != "samples" && args[k] != "seed") {
          const int t = parse_int(args[k], "compute " + id + " region/phi type");
          if (t < 1 || t > ntypes)
            throw InputError("compute " + id + " region/phi: atom type " + args[k] + " is outside 1.." +
                             std::to_string(ntypes));
          types_.push_back(t);
          ++k;
        }
        if (types_.empty())
          throw InputError("compute " + id + " region/phi: 'type' needs at least one atom type");
      } else if (key == "clump" && k + 1 < args.size()) {
        if (args[k + 1] == "mc")
          mc_ = true;
        else if (args[k + 1] == "scale")
          mc_ = false;
        else
          throw InputError("compute " + id + " region/phi: clump must be mc or scale, not '" + args[k + 1] +
                           "'");
        k += 2;
      } else if (key == "samples" && k + 1 < args.size()) {
        samples_ = parse_int(args[k + 1], "compute " + id + " region/phi samples");
        if (samples_ < 1) throw InputError("compute " + id + " region/phi: samples must be positive");
        k += 2;
      } else if (key == "seed" && k + 1 < args.size()) {
        seed_ = static_cast<std::uint64_t>(parse_int(args[k + 1], "compute " + id + " region/phi seed"));
        k += 2;
      } else {
        throw InputError("compute " + id + " region/phi: unknown or incomplete keyword '" + key +
                         "'; usage: " + usage);
      }
    }
    if (types_.empty())
      for (int t = 1; t <= ntypes; ++t)
        types_.push_back(t);
    slot_.assign(static_cast<std::size_t>(ntypes) + 1, -1);
    for (std::size_t s = 0; s < types_.size(); ++s)
      slot_[types_[s]] = static_cast<int>(s);
    scalar_flag = true;
    size_vector = static_cast<int>(types_.size());
    vector.assign(types_.size(), 0.0);
    extensive = false;
  }

  void init() override { block(); }

  double compute_scalar() override {
    evaluate();
    return scalar;
  }

  void compute_vector() override { evaluate(); }

 private:
  struct Block {
    Vec3 lo, hi;
    double volume;
  };

  /// The region as a block (looked up every time: it may be redefined).
  Block block() const {
    const Region* region = engine_.domain->region_or_error(region_id_, "compute " + id);
    Block b;
    if (region->style != "block")
      throw InputError("compute " + id + " region/phi: region " + region_id_ + " is a " + region->style +
                       " region; region/phi needs a block region");
    if (!region->bounds(b.lo, b.hi) || region->volume() <= 0.0)
      throw InputError("compute " + id + " region/phi: region " + region_id_ +
                       " must be a finite block with side in and a positive volume");
    b.volume = region->volume();
    return b;
  }

  /// Periodic shifts (as vectors) of an object of centre c and radius R whose
  /// image may meet the block.
  std::vector<Vec3> shifts(const Vec3& c, double R, const Block& blk) const {
    const Domain& dom = *engine_.domain;
    std::vector<double> s[3];
    for (int d = 0; d < 3; ++d) {
      const bool per = dom.periodic[d] && dom.prd[d] > 0.0;
      for (int m = per ? -1 : 0; m <= (per ? 1 : 0); ++m) {
        const double off = m * dom.prd[d];
        if (c[d] + off + R > blk.lo[d] && c[d] + off - R < blk.hi[d]) s[d].push_back(off);
      }
    }
    std::vector<Vec3> out;
    for (double a : s[0])
      for (double b : s[1])
        for (double c2 : s[2])
          out.emplace_back(a, b, c2);
    return out;
  }

  static bool in_block(const Vec3& p, const Block& blk) {
    for (int d = 0; d < 3; ++d)
      if (p[d] < blk.lo[d] || p[d] > blk.hi[d]) return false;
    return true;
  }

  void evaluate() {
    const Block blk = block();
    const Domain& dom = *engine_.domain;
    for (int d = 0; d < 3; ++d) {
      if (dom.periodic[d] && blk.hi[d] - blk.lo[d] > dom.prd[d] * (1.0 + 1e-12))
        throw InputError("compute " + id + " region/phi: block " + region_id_ +
                         " is longer than the periodic box along " + std::string(1, "xyz"[d]));
    }
    const Particles& p = *engine_.particles;
    Clumps* ms = engine_.clumps;
    if (ms) ms->sync_bodies();  // body b is evaluated on rank b mod nprocs
    const Bodies* bodies = ms ? &ms->bodies() : nullptr;
    const int nb = bodies ? bodies->size() : 0;
    const std::size_t nt = types_.size();
    // local sums: [0, nt) per listed type, nt: all types
    std::vector<double> local(nt + 1, 0.0), global(nt + 1, 0.0);
    std::vector<int> mark(static_cast<std::size_t>(nb), 0), in_group(static_cast<std::size_t>(nb), 0);
    auto add = [&](int type, double v) {
      local[nt] += v;
      if (type >= 0 && type < static_cast<int>(slot_.size()) && slot_[type] >= 0) local[slot_[type]] += v;
    };
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      if (bodies && p.body[i] >= 0) {
        const int b = bodies->find(p.body[i]);
        if (b >= 0) {
          mark[b] = 1;
          continue;
        }
      }
      double v = 0.0;
      for (const Vec3& s : shifts(p.x[i], p.radius[i], blk))
        v += sphere_box_volume(p.x[i] + s, p.radius[i], blk.lo, blk.hi);
      add(p.type[i], v);
    }
    if (nb > 0) {
      MPI_Allreduce(mark.data(), in_group.data(), nb, MPI_INT, MPI_MAX, engine_.world);
      for (int b = 0; b < nb; ++b) {
        // every rank holds every body: body b is evaluated on rank b mod nprocs
        if (!in_group[b] || b % engine_.nprocs != engine_.rank) continue;
        add(bodies->type[b], clump_volume(*ms, b, blk));
      }
    }
    MPI_Allreduce(local.data(), global.data(), static_cast<int>(nt + 1), MPI_DOUBLE, MPI_SUM, engine_.world);
    scalar = global[nt] / blk.volume;
    vector.resize(nt);
    for (std::size_t s = 0; s < nt; ++s)
      vector[s] = global[s] / blk.volume;
  }

  /// Volume of the union of body b's sub-spheres inside the block (all periodic images).
  double clump_volume(const Clumps& ms, int b, const Block& blk) const {
    const Bodies& B = ms.bodies();
    const Vec3 xc = ms.wrapped_centre(b);
    const Eigen::Matrix3d rot = B.rotation(b);
    const int s0 = B.sphere_start[b], n = B.nspheres[b];
    std::vector<Vec3> c(static_cast<std::size_t>(n));
    std::vector<double> r(static_cast<std::size_t>(n));
    double R = 0.0, vsum = 0.0;
    Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
    for (int k = 0; k < n; ++k) {
      c[k] = xc + rot * B.offsets[s0 + k];
      r[k] = B.radii[s0 + k];
      R = std::max(R, (c[k] - xc).norm() + r[k]);
      vsum += 4.0 / 3.0 * kPi * r[k] * r[k] * r[k];
      lo = lo.cwiseMin(c[k] - Vec3::Constant(r[k]));
      hi = hi.cwiseMax(c[k] + Vec3::Constant(r[k]));
    }
    const double vbody = B.volume[b];
    const std::vector<Vec3> images = shifts(xc, R, blk);
    // exact when every image is wholly inside or wholly outside the block
    int inside = 0;
    bool straddles = false;
    for (const Vec3& s : images) {
      bool all_in = true, any_in = true;
      for (int d = 0; d < 3; ++d) {
        if (lo[d] + s[d] < blk.lo[d] || hi[d] + s[d] > blk.hi[d]) all_in = false;
        if (hi[d] + s[d] <= blk.lo[d] || lo[d] + s[d] >= blk.hi[d]) any_in = false;
      }
      if (all_in)
        ++inside;
      else if (any_in)
        straddles = true;
    }
    if (!straddles) return inside * vbody;
    if (!mc_) {
      if (vsum <= 0.0) return 0.0;
      double v = 0.0;
      for (const Vec3& s : images)
        for (int k = 0; k < n; ++k)
          v += sphere_box_volume(c[k] + s, r[k], blk.lo, blk.hi);
      return v * (vbody / vsum);
    }
    // Monte Carlo: fraction of points uniform in the union that fall in the block
    SplitMix rng{seed_ * 0x2545f4914f6cdd1dULL ^
                 (static_cast<std::uint64_t>(B.tag[b]) + 0x632be59bd9b4e019ULL)};
    const Vec3 ext = hi - lo;
    long long accepted = 0, hit = 0, tries = 0;
    const long long max_tries = 1000LL * samples_;
    while (accepted < samples_ && tries < max_tries) {
      ++tries;
      const Vec3 q(lo[0] + ext[0] * rng.uniform(), lo[1] + ext[1] * rng.uniform(),
                   lo[2] + ext[2] * rng.uniform());
      bool in_union = false;
      for (int k = 0; k < n && !in_union; ++k)
        in_union = (q - c[k]).squaredNorm() <= r[k] * r[k];
      if (!in_union) continue;
      ++accepted;
      for (const Vec3& s : images)
        if (in_block(q + s, blk)) ++hit;
    }
    return accepted > 0 ? vbody * static_cast<double>(hit) / static_cast<double>(accepted) : 0.0;
  }

  std::string region_id_;
  std::vector<int> types_;  // reported types in order
  std::vector<int> slot_;   // type -> index in types_ (-1: not reported)
  bool mc_ = true;
  long long samples_ = 40000;
  std::uint64_t seed_ = 4357;
};

}  // namespace

GRANARY_COMPUTE_STYLE("region-phi", ComputeRegionPhi);
GRANARY_COMPUTE_STYLE("region/phi", ComputeRegionPhi);  // same style, LAMMPS-like spelling

}  // namespace granary
