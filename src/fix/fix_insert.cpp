#include "comm/collectives.h"
#include "fix/fix_insert.h"

#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/resources.h"
#include "core/update.h"
#include "domain/domain.h"
#include "geometry/sphere_grid.h"
#include "domain/region.h"
#include "fix/fix_particledistribution_discrete.h"
#include "fix/fix_wall_gran.h"
#include "core/modify.h"
#include "neighbor/neighbor.h"
#include "particles/clumps.h"
#include "particles/particles.h"

namespace granary {

namespace {

// ------------------------------------------------------------ all_in test

/// Unit directions of a geodesic sphere (icosahedron, two subdivisions) and the
/// factor that puts its vertices far enough out for the polyhedron to contain
/// the unit sphere: every face plane is at least 1 from the centre.
struct Geodesic {
  std::vector<Vec3> dirs;
  double scale = 1.0;
  Geodesic() {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (auto& x : v)
      x.normalize();
    std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                         {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                         {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                         {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int level = 0; level < 2; ++level) {
      std::map<std::pair<int, int>, int> mid;
      auto midpoint = [&](int a, int b) {
        const auto key = std::make_pair(std::min(a, b), std::max(a, b));
        auto it = mid.find(key);
        if (it != mid.end()) return it->second;
        v.push_back((v[a] + v[b]).normalized());
        const int idx = static_cast<int>(v.size()) - 1;
        mid[key] = idx;
        return idx;
      };
      std::vector<std::array<int, 3>> g;
      for (const auto& tri : f) {
        const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
        g.push_back({tri[0], a, c});
        g.push_back({tri[1], b, a});
        g.push_back({tri[2], c, b});
        g.push_back({a, b, c});
      }
      f.swap(g);
    }
    // Each ray from the centre crosses a face at least as far out as the
    // face's plane, so the ball of radius dmin lies inside the polyhedron.
    double dmin = 1.0;
    for (const auto& tri : f) {
      const Vec3 n = (v[tri[1]] - v[tri[0]]).cross(v[tri[2]] - v[tri[0]]).normalized();
      dmin = std::min(dmin, std::fabs(n.dot(v[tri[0]])));
    }
    dirs = v;
    scale = 1.0 / dmin * (1.0 + 1e-12);
  }
};

const Geodesic& geodesic() {
  static const Geodesic g;
  return g;
}

/// Whether the sphere (c, r) lies inside the region. Exact for convex regions
/// up to the polyhedra used: the circumscribed cube (exact for blocks), else a
/// circumscribed geodesic polyhedron (within about 1.2% of r for curved faces).
bool sphere_inside(const Region& reg, const Vec3& c, double r) {
  if (!reg.match(c)) return false;
  bool cube = true;
  for (int k = 0; k < 8 && cube; ++k) {
    const Vec3 corner(c[0] + ((k & 1) ? r : -r), c[1] + ((k & 2) ? r : -r), c[2] + ((k & 4) ? r : -r));
    cube = reg.match(corner);
  }
  if (cube) return true;
  const Geodesic& g = geodesic();
  const double R = r * g.scale;
  for (const Vec3& u : g.dirs)
    if (!reg.match(c + R * u)) return false;
  return true;
}

// ------------------------------------------------------- overlap search

/// Position wrapped into the periodic box (a copy; image flags are not kept).
Vec3 wrapped(const Domain& dom, const Vec3& x) {
  Vec3 y = x;
  int image = Particles::image_pack(0, 0, 0);
  dom.remap(y, image);
  return y;
}

// ------------------------------------------------ creating the particles

struct NewSphere {
  tagint id = 0;
  int type = 1, mask = 1;
  Vec3 x, v, omega;
  double radius = 0.0, density = 0.0;
  tagint body = -1;
};

/// Append owned particles. Runs in pre_exchange of a reneighbouring step, when
/// the contact history has been saved by particle ids and the ghosts are gone.
void add_owned(Engine& e, const std::vector<NewSphere>& add,
               const std::vector<std::pair<int, double>>& fields) {
  Particles& p = *e.particles;
  const int nadd = static_cast<int>(add.size());
  if (nadd == 0) return;
  const int nold = p.nlocal;
  p.resize(nold + nadd);
  for (int k = 0; k < nadd; ++k) {
    const int i = nold + k;
    const NewSphere& s = add[k];
    p.id[i] = s.id;
    p.type[i] = s.type;
    p.mask[i] = s.mask;
    p.x[i] = s.x;
    p.v[i] = s.v;
    p.f[i].setZero();
    p.omega[i] = s.omega;
    p.torque[i].setZero();
    p.radius[i] = s.radius;
    p.density[i] = s.density;
    p.rmass[i] = Particles::sphere_mass(s.radius, s.density);
    p.body[i] = s.body;
    p.image[i] = Particles::image_pack(0, 0, 0);
    p.init_extras(i);
    for (const auto& [k, v] : fields)
      p.extras[k].data[i] = v;
  }
  p.nlocal += nadd;
  p.map_clear();
}

}  // namespace

// ================================================================ FixInsert

FixInsert::FixInsert(Engine& engine, const Args& args, const std::map<std::string, int>& style_keywords,
                     const std::string& usage, bool needs_region)
    : Fix(engine, args) {
  const std::string what = label();
  bool have_seed = false;
  for (std::size_t k = 3; k < args.size(); ++k) {
    const std::string& w = args[k];
    auto value = [&]() -> const std::string& {
      if (k + 1 >= args.size()) throw InputError(what + ": keyword '" + w + "' needs a value");
      return args[++k];
    };
    auto vec3 = [&](const std::string& name) {
      Vec3 v;
      for (int d = 0; d < 3; ++d)
        v[d] = parse_double(value(), what + " " + name);
      return v;
    };
    if (w == "seed") {
      seed_ = parse_int(value(), what + " seed");
      if (seed_ <= 0) throw InputError(what + ": the seed must be a positive integer");
      have_seed = true;
    } else if (w == "distributiontemplate") {
      dist_id_ = value();
    } else if (w == "verbose") {
      verbose_ = parse_bool(value(), what + " verbose");
    } else if (w == "maxattempt") {
      const long long m = parse_int(value(), what + " maxattempt");
      if (m < 1) throw InputError(what + ": maxattempt must be at least 1");
      maxattempt_ = static_cast<int>(std::min<long long>(m, 1000000000));
    } else if (w == "insert_every") {
      const std::string& v = value();
      if (v == "once") {
        insert_every_ = 0;
      } else {
        const long long n = parse_int(v, what + " insert_every");
        if (n < 1) throw InputError(what + ": insert_every must be 'once' or a positive number of steps");
        insert_every_ = static_cast<int>(n);
      }
    } else if (w == "start") {
      start_ = parse_int(value(), what + " start");
      if (start_ < 0) throw InputError(what + ": start must be a step number >= 0");
    } else if (w == "overlapcheck") {
      overlapcheck_ = parse_bool(value(), what + " overlapcheck");
    } else if (w == "all_in") {
      all_in_ = parse_bool(value(), what + " all_in");
    } else if (w == "random_distribute") {
      const std::string& v = value();
      if (v == "exact")
        exact_ = true;
      else if (v == "uncorrelated")
        exact_ = false;
      else
        throw InputError(what + ": random_distribute must be exact or uncorrelated, got '" + v + "'");
    } else if (w == "compress_tags") {
      if (parse_bool(value(), what + " compress_tags")) {
        throw InputError(what + ": compress_tags yes (renumbering all particles) is not supported");
      }
    } else if (w == "check_dist_from_subdomain_border") {
      parse_bool(value(), what + " check_dist_from_subdomain_border");  // every rank checks everything
    } else if (w == "vel") {
      const std::string& s = value();
      if (s == "constant") {
        vel_style_ = VelStyle::Constant;
        vel_ = vec3("vel constant");
      } else if (s == "uniform" || s == "gaussian") {
        vel_style_ = s == "uniform" ? VelStyle::Uniform : VelStyle::Gaussian;
        vel_ = vec3("vel " + s);
        vel_fluct_ = vec3("vel " + s + " fluctuation");
        for (int d = 0; d < 3; ++d)
          if (vel_fluct_[d] < 0) throw InputError(what + ": vel " + s + " fluctuations must not be negative");
      } else {
        throw InputError(what +
                         ": vel takes constant VX VY VZ, uniform VX VY VZ DVX DVY DVZ or gaussian "
                         "VX VY VZ SX SY SZ, got '" +
                         s + "'");
      }
    } else if (w == "omega") {
      const std::string& s = value();
      if (s != "constant") throw InputError(what + ": omega takes constant WX WY WZ, got '" + s + "'");
      omega_ = vec3("omega constant");
    } else if (w == "orientation") {
      const std::string& s = value();
      if (s == "random") {
        orientation_ = Orientation::Random;
      } else if (s == "template") {
        orientation_ = Orientation::Template;
      } else if (s == "constant") {
        double q[4];
        for (double& c : q)
          c = parse_double(value(), what + " orientation constant");
        quat_ = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
        if (!(quat_.norm() > 0.0))
          throw InputError(what + ": orientation constant needs a non-zero quaternion");
        quat_.normalize();
        orientation_ = Orientation::Constant;
      } else {
        throw InputError(what + ": orientation must be random, template or constant Q0 Q1 Q2 Q3, got '" + s +
                         "'");
      }
    } else if (w == "region") {
      region_id_ = value();
    } else if (w == "ntry_mc") {
      ntry_mc_ = parse_int(value(), what + " ntry_mc");
      if (ntry_mc_ < 1) throw InputError(what + ": ntry_mc must be at least 1");
    } else if (w == "set_property") {
      const std::string name = value();
      set_property_.emplace_back(name, parse_double(value(), what + " set_property " + name));
    } else if (style_keywords.count(w)) {
      const int nv = style_keywords.at(w);
      Args vals;
      for (int i = 0; i < nv; ++i)
        vals.push_back(value());
      style_values_[w] = vals;
    } else {
      std::vector<std::string> known = {
          "seed",   "distributiontemplate", "verbose", "maxattempt", "insert_every", "start",  "overlapcheck",
          "all_in", "random_distribute",    "vel",     "omega",      "orientation",  "region", "ntry_mc"};
      for (const auto& kv : style_keywords)
        known.push_back(kv.first);
      const std::string hint = did_you_mean(w, known);
      throw InputError(what + ": unknown keyword '" + w + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + usage);
    }
  }
  if (!have_seed) throw InputError(what + ": the seed keyword is required; usage: " + usage);
  if (dist_id_.empty())
    throw InputError(what + ": the distributiontemplate keyword is required; usage: " + usage);
  if (needs_region && region_id_.empty())
    throw InputError(what + ": the region keyword is required; usage: " + usage);
  if (!needs_region && !region_id_.empty())
    throw InputError(what +
                     ": takes no region keyword (it builds its own insertion volume); usage: " + usage);
  Fix* d = engine.modify->find_fix(dist_id_);
  if (!d || !dynamic_cast<FixParticleDistributionDiscrete*>(d)) {
    throw InputError(what + ": distributiontemplate " + dist_id_ +
                     (d ? " is not a fix particledistribution/discrete" : " is not defined") +
                     "; define it with fix ID group particledistribution/discrete before this fix");
  }
  if (needs_region) engine.domain->region_or_error(region_id_, what);
  gen_.seed(static_cast<std::uint64_t>(seed_));
  seen_step_ = engine.update->ntimestep;
  size_vector = 2;
  restart_global = true;
}

double FixInsert::uniform() {
  return static_cast<double>(gen_() >> 11) * 0x1.0p-53;
}

FixParticleDistributionDiscrete& FixInsert::dist() const {
  Fix* d = engine_.modify->find_fix(dist_id_);
  auto* dd = d ? dynamic_cast<FixParticleDistributionDiscrete*>(d) : nullptr;
  if (!dd) throw InputError(label() + ": distributiontemplate " + dist_id_ + " no longer exists");
  return *dd;
}

Region& FixInsert::region() const {
  return *engine_.domain->region_or_error(region_id_, label());
}

void FixInsert::init() {
  const std::string what = label();
  set_fields_.clear();
  for (const auto& [name, v] : set_property_) {
    const Particles& p = *engine_.particles;
    const int k = p.find_field(name);
    if (k < 0 || !p.extras[k].settable || p.extras[k].ncomp != 1)
      throw InputError(
          what + ": set_property " + name +
          " names no scalar per-particle property; define it with fix property/atom (or the fix that "
          "owns it, e.g. fix heat/gran for Temp) before the run");
    set_fields_.emplace_back(k, v);
  }
  FixParticleDistributionDiscrete& d = dist();
  for (int i = 0; i < d.ntemplates(); ++i)
    d.templ(i).init();
  if (d.any_multisphere() && !engine_.clumps) {
    throw InputError(what + ": distribution " + dist_id_ +
                     " has a multisphere template; define fix multisphere before the run");
  }
  Domain& dom = *engine_.domain;
  Region& reg = region();

  // region volume inside the box: exact where the region knows it and lies
  // inside the box, else Monte Carlo (a generator of its own, so that ntry_mc
  // does not change the particles placed)
  Vec3 lo = dom.boxlo, hi = dom.boxhi, rlo, rhi;
  bool inside_box = false;
  if (reg.bounds(rlo, rhi)) {
    inside_box = true;
    for (int d3 = 0; d3 < 3; ++d3) {
      inside_box = inside_box && rlo[d3] >= dom.boxlo[d3] && rhi[d3] <= dom.boxhi[d3];
      lo[d3] = std::max(lo[d3], rlo[d3]);
      hi[d3] = std::min(hi[d3], rhi[d3]);
    }
  }
  for (int d3 = 0; d3 < 3; ++d3) {
    if (!(hi[d3] > lo[d3])) throw InputError(what + ": region " + region_id_ + " does not overlap the box");
  }
  const double exact = reg.volume();
  if (inside_box && exact >= 0.0) {
    region_volume_ = exact;
  } else {
    std::mt19937_64 mc(static_cast<std::uint64_t>(seed_) ^ 0x5DEECE66Dull);
    long long hits = 0;
    for (long long k = 0; k < ntry_mc_; ++k) {
      Vec3 x;
      for (int d3 = 0; d3 < 3; ++d3)
        x[d3] = lo[d3] + static_cast<double>(mc() >> 11) * 0x1.0p-53 * (hi[d3] - lo[d3]);
      hits += reg.match(x) ? 1 : 0;
    }
    region_volume_ = (hi - lo).prod() * static_cast<double>(hits) / static_cast<double>(ntry_mc_);
    if (hits == 0) {
      throw InputError(what + ": none of " + std::to_string(ntry_mc_) +
                       " random points of the box lies in region " + region_id_ +
                       "; check the region (or raise ntry_mc for a very thin one)");
    }
  }

  // the step counter was changed since this fix last saw it (reset_timestep,
  // also before the fix was defined again after read_restart): the schedule
  // moves with it, so that the number of steps to the next insertion is kept
  const std::int64_t now = engine_.update->ntimestep;
  if (!finished_ && next_step_ >= 0 && now != seen_step_) next_step_ += now - seen_step_;
  seen_step_ = now;

  // first insertion: the first step of this run, or `start`
  if (!finished_ && next_step_ <= engine_.update->ntimestep) {
    next_step_ = std::max<std::int64_t>(engine_.update->ntimestep + 1, start_);
  }
}

void FixInsert::post_integrate() {
  const std::int64_t step = engine_.update->ntimestep;
  seen_step_ = step;
  if (finished_) return;
  if (next_step_ < step) next_step_ = std::max<std::int64_t>(step, start_);  // runs without setup (pre no)
  if (step == next_step_) engine_.neighbor->force_rebuild = true;
}

void FixInsert::pre_exchange() {
  if (finished_ || !engine_.update->running) return;
  const std::int64_t step = engine_.update->ntimestep;
  if (step != next_step_) return;
  if (region_volume_ <= 0.0) init();
  const long long n = count_to_insert();
  const Result r = insert(n);
  ninserted_ += r.placed;
  mass_inserted_ += r.mass;
  inserted_batch(r);
  if (done_after_insertion()) {
    finished_ = true;
  } else {
    next_step_ = step + std::max(insert_every_, 1);
  }
}

long long FixInsert::round_stochastic(double x) {
  if (!(x > 0.0)) return 0;
  const double f = std::floor(x);
  return static_cast<long long>(f) + (uniform() < x - f ? 1 : 0);
}

void FixInsert::count_in_region(double& number, double& mass, double& volume) const {
  const Particles& p = *engine_.particles;
  const Region& reg = region();
  double local[3] = {0, 0, 0}, all[3];
  std::vector<long long> bodies;
  for (int i = 0; i < p.nlocal; ++i) {
    if (!reg.match(wrapped(*engine_.domain, p.x[i]))) continue;  // not yet remapped at pre_exchange
    if (p.body[i] >= 0)
      bodies.push_back(static_cast<long long>(p.body[i]));
    else
      local[0] += 1.0;
    local[1] += p.rmass[i];
    // a clump's sub-spheres overlap: each carries its share of the clump's
    // solid volume (share of its mass over the clump density), not its sphere volume
    local[2] += p.body[i] >= 0 && p.density[i] > 0.0
                    ? p.rmass[i] / p.density[i]
                    : 4.0 / 3.0 * M_PI * p.radius[i] * p.radius[i] * p.radius[i];
  }
  MPI_Allreduce(local, all, 3, MPI_DOUBLE, MPI_SUM, engine_.world);
  // a multisphere particle counts once, whichever ranks hold its spheres
  std::vector<long long> allb = allgather(engine_.world, bodies);
  std::sort(allb.begin(), allb.end());
  const double nbodies = static_cast<double>(std::unique(allb.begin(), allb.end()) - allb.begin());
  number = all[0] + nbodies;
  mass = all[1];
  volume = all[2];
}

FixInsert::Result FixInsert::insert(long long n) {
  Result res;
  res.requested = n;
  if (n <= 0) return res;
  Engine& e = engine_;
  Domain& dom = *e.domain;
  Particles& p = *e.particles;
  Region& reg = region();
  FixParticleDistributionDiscrete& d = dist();
  // each template is at least one sphere: refuse what cannot fit before drawing
  check_particle_memory(e, static_cast<double>(n), "fix " + id + " " + style);

  auto batch = d.draw_batch(n, exact_);

  // where candidates are drawn: the region's bounds inside the box
  Vec3 lo = dom.boxlo, hi = dom.boxhi, rlo, rhi;
  if (reg.bounds(rlo, rhi)) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::max(lo[k], rlo[k]);
      hi[k] = std::min(hi[k], rhi[k]);
    }
  }

  double rnew = 0.0, rbound = 0.0;
  for (const auto& b : batch) {
    for (double r : b.particle.radii)
      rnew = std::max(rnew, r);
    rbound = std::max(rbound, b.particle.bounding_radius);
  }
  double rold_local = 0.0, rold = 0.0;
  for (int i = 0; i < p.nlocal; ++i)
    rold_local = std::max(rold_local, p.radius[i]);
  MPI_Allreduce(&rold_local, &rold, 1, MPI_DOUBLE, MPI_MAX, e.world);

  SphereGrid grid(dom, std::max(rnew, rold));
  std::vector<const FixWallGran*> walls;
  int newmask_all = groupbit | 1;
  if (overlapcheck_) {
    // existing particles that can touch the region: every rank gets them all
    const double margin = rbound + rold;
    std::vector<double> mine;
    for (int i = 0; i < p.nlocal; ++i) {
      const Vec3 x = wrapped(dom, p.x[i]);
      bool near = false;
      for (int sx = -1; sx <= 1 && !near; ++sx) {
        for (int sy = -1; sy <= 1 && !near; ++sy) {
          for (int sz = -1; sz <= 1 && !near; ++sz) {
            const int s[3] = {sx, sy, sz};
            bool ok = true;
            for (int k = 0; k < 3 && ok; ++k) {
              if (s[k] != 0 && !dom.periodic[k]) ok = false;
              const double xk = x[k] + s[k] * dom.prd[k];
              ok = ok && xk >= lo[k] - margin && xk <= hi[k] + margin;
            }
            near = ok;
          }
        }
      }
      if (!near) continue;
      mine.insert(mine.end(), {x[0], x[1], x[2], p.radius[i]});
    }
    std::vector<double> all = allgather(e.world, mine);
    for (std::size_t k = 0; k + 3 < all.size(); k += 4)
      grid.add(Vec3(all[k], all[k + 1], all[k + 2]), all[k + 3]);
    // primitive walls (mesh walls are not checked: contact() describes primitives only)
    for (const auto& f : e.modify->fixes)
      if (auto* w = dynamic_cast<const FixWallGran*>(f.get()); w && !w->mesh_form()) walls.push_back(w);
  }

  struct Placed {
    std::size_t b;
    Vec3 x;
    Eigen::Quaterniond q;
  };
  std::vector<Placed> placed;
  std::vector<Vec3> centres;
  constexpr long long kMaxRegionMisses = 1000000;
  bool region_empty = false;
  // Tries of one particle; `budget` counts all tries of the batch.
  long long budget = static_cast<long long>(batch.size()) * maxattempt_;
  auto try_place = [&](std::size_t b, long long tries) {
    const TemplateParticle& tp = batch[b].particle;
    const int mask = newmask_all | batch[b].groupbits;
    const bool several = tp.offsets.size() > 1 || tp.multisphere;
    for (long long attempt = 0; attempt < tries && budget > 0 && !region_empty; ++attempt) {
      --budget;
      Vec3 x;
      long long misses = 0;
      while (true) {
        for (int k = 0; k < 3; ++k)
          x[k] = lo[k] + uniform() * (hi[k] - lo[k]);
        if (reg.match(x)) break;
        if (++misses >= kMaxRegionMisses) {
          region_empty = true;
          break;
        }
      }
      if (region_empty) break;
      const Vec3 shift = candidate_shift(tp.bounding_radius);
      x += shift;
      // template: the particle as its template was given (a clump file's
      // coordinates), not its principal axes; constant: that frame rotated
      // by the quaternion (both as LIGGGHTS)
      Eigen::Quaterniond q = tp.frame;
      if (several) {
        if (orientation_ == Orientation::Constant) {
          q = quat_ * tp.frame;
        } else if (orientation_ == Orientation::Random) {
          // uniform random rotation (Shoemake)
          const double u1 = uniform(), u2 = uniform(), u3 = uniform();
          const double a = std::sqrt(1.0 - u1), c = std::sqrt(u1);
          q = Eigen::Quaterniond(c * std::cos(2 * M_PI * u3), a * std::sin(2 * M_PI * u2),
                                 a * std::cos(2 * M_PI * u2), c * std::sin(2 * M_PI * u3));
        }
      }
      centres.clear();
      for (const Vec3& off : tp.offsets)
        centres.push_back(several ? Vec3(x + q * off) : x);
      bool ok = true;
      for (std::size_t k = 0; k < centres.size() && ok; ++k) {
        const Vec3& c = centres[k];
        const double r = tp.radii[k];
        for (int dd = 0; dd < 3 && ok; ++dd) {
          // a centre outside a fixed boundary would be lost
          const bool fixed_lo = dom.boundary[dd][0] == 'f', fixed_hi = dom.boundary[dd][1] == 'f';
          if ((fixed_lo && c[dd] < dom.boxlo[dd]) || (fixed_hi && c[dd] > dom.boxhi[dd])) ok = false;
        }
        if (ok && all_in_) ok = sphere_inside(reg, c - shift, r);
        if (ok && overlapcheck_) {
          ok = !grid.overlaps(wrapped(dom, c), r);
          for (const FixWallGran* w : walls) {
            if (!ok) break;
            if (!(w->groupbit & mask)) continue;
            double overlap = 0.0;
            Vec3 nrm;
            if (w->contact(c, r, overlap, nrm) && overlap > 0.0) ok = false;
          }
        }
      }
      if (!ok) continue;
      for (std::size_t k = 0; k < centres.size(); ++k)
        grid.add(wrapped(dom, centres[k]), tp.radii[k]);
      placed.push_back({b, x, q});
      return true;
    }
    return false;
  };
  // maxattempt tries per particle, plus those left unused by the particles
  // before it (at most n * maxattempt tries in all, as in LIGGGHTS): a
  // particle that is hard to place gets more tries, and every particle after it
  // still gets maxattempt
  for (std::size_t b = 0; b < batch.size(); ++b) {
    const long long later = static_cast<long long>(batch.size() - b - 1) * maxattempt_;
    try_place(b, budget - later);
  }
  if (region_empty) {
    e.logger->warning(label() + ": no point of region " + region_id_ + " found in " +
                      std::to_string(kMaxRegionMisses) +
                      " random tries inside its bounds; insertion stopped");
  }

  // velocities, ids, and the spheres this rank owns
  long long maxid_local = static_cast<long long>(p.max_local_id()), maxid = 0;
  MPI_Allreduce(&maxid_local, &maxid, 1, MPI_LONG_LONG, MPI_MAX, e.world);
  long long maxbody_local = -1, maxbody = -1;
  for (int i = 0; i < p.nlocal; ++i)
    maxbody_local = std::max<long long>(maxbody_local, p.body[i]);
  MPI_Allreduce(&maxbody_local, &maxbody, 1, MPI_LONG_LONG, MPI_MAX, e.world);
  tagint next_id = static_cast<tagint>(maxid + 1);
  tagint next_body = static_cast<tagint>(std::max(maxbody, 0LL) + 1);  // body ids start at 1

  struct Body {
    tagint body_id, first_id;
    std::size_t b;
    Vec3 x, v, w;
    Eigen::Quaterniond q;
  };
  std::vector<Body> bodies;
  std::vector<NewSphere> mine;
  long long nspheres = 0;
  double rplaced = 0.0;
  for (const Placed& pl : placed) {
    const TemplateParticle& tp = batch[pl.b].particle;
    const int mask = newmask_all | batch[pl.b].groupbits;
    Vec3 v = vel_;
    if (vel_style_ == VelStyle::Uniform) {
      for (int k = 0; k < 3; ++k)
        v[k] += vel_fluct_[k] * (2.0 * uniform() - 1.0);
    } else if (vel_style_ == VelStyle::Gaussian) {
      for (int k = 0; k < 3; ++k) {
        const double u1 = 1.0 - uniform(), u2 = uniform();  // Box-Muller, u1 in (0, 1]
        v[k] += vel_fluct_[k] * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
      }
    }
    const bool body = tp.multisphere;
    const tagint first = next_id;
    for (std::size_t k = 0; k < tp.offsets.size(); ++k) {
      NewSphere s;
      s.id = next_id++;
      s.type = tp.type;
      s.mask = mask;
      const Vec3 arm = (tp.offsets.size() > 1 || body) ? Vec3(pl.q * tp.offsets[k]) : Vec3(0, 0, 0);
      s.x = pl.x + arm;
      s.v = v + omega_.cross(arm);
      s.omega = omega_;
      s.radius = tp.radii[k];
      s.density = tp.density;
      s.body = body ? next_body : -1;
      rplaced = std::max(rplaced, s.radius);
      ++nspheres;
      if (e.comm->owner_of(s.x) == e.rank) mine.push_back(s);
    }
    if (body) bodies.push_back({next_body++, first, pl.b, pl.x, v, omega_, pl.q});
    res.mass += tp.mass;
    res.volume += tp.volume;
  }
  res.placed = static_cast<long long>(placed.size());
  add_owned(e, mine, set_fields_);
  p.natoms += nspheres;

  if (!bodies.empty()) {
    BodyRegistrar* registrar = e.clumps ? &e.clumps->registrar() : nullptr;
    if (!registrar) {
      throw RunError(label() + ": a multisphere template needs fix multisphere, which is not defined");
    }
    for (const Body& bd : bodies)
      registrar->add_body(bd.body_id, bd.first_id, batch[bd.b].particle, bd.x, bd.q, bd.v, bd.w);
  }

  // the neighbour cutoff must cover the new spheres from this rebuild on
  Neighbor& nb = *e.neighbor;
  if (rplaced > nb.rmax) {
    nb.rmax = rplaced;
    nb.cutneighmax = nb.cutoff_for(nb.rmax);
  }
  return res;
}

double FixInsert::compute_vector(int i) {
  if (i == 0) return static_cast<double>(ninserted_);
  if (i == 1) return mass_inserted_;
  return 0.0;
}

std::int64_t FixInsert::next_step() const {
  if (finished_) return -1;
  // a change of the step counter not yet seen by init moves the schedule too
  return next_step_ >= 0 ? next_step_ + (engine_.update->ntimestep - seen_step_) : next_step_;
}

void FixInsert::pack_restart(std::string& out) const {
  std::ostringstream os;
  os.precision(17);
  const std::int64_t next = finished_ ? next_step_ : next_step();
  os << ninserted_ << ' ' << mass_inserted_ << ' ' << next << ' ' << (finished_ ? 1 : 0) << ' ' << gen_ << ' '
     << engine_.update->ntimestep;
  out = os.str();
}

void FixInsert::unpack_restart(const std::string& in) {
  std::istringstream is(in);
  long long n = 0;
  double m = 0.0;
  long long next = -1;
  int fin = 0;
  std::mt19937_64 g;
  if (!(is >> n >> m >> next >> fin >> g)) return;
  ninserted_ = n;
  mass_inserted_ = m;
  next_step_ = next;
  finished_ = fin != 0;
  gen_ = g;
  // the step the file was written at (files without it: the current step)
  long long written = 0;
  seen_step_ = (is >> written) ? written : engine_.update->ntimestep;
}

}  // namespace granary
