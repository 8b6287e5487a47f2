// Commands that create, modify and delete particles: lattice, create_atoms,
// set, velocity, delete_atoms.
//
// Everything random here is independent of the number of MPI ranks: random
// insertion draws the same sequence of points on every rank (each rank keeps
// the points in its subdomain), and per-particle random choices are hashed
// from the seed and the particle id.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include <Eigen/Dense>

#include "comm/collectives.h"
#include "core/engine.h"
#include "neighbor/contact_history.h"
#include "pair/pair.h"
#include "pair/force.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "domain/sphere_grid.h"
#include "domain/groups.h"
#include "core/update.h"
#include "domain/region.h"
#include "fix/fix_multisphere.h"
#include "fix/modify.h"
#include "particles/particles.h"

namespace granary {

namespace {

// -------------------------------------------------------------- utilities

void require_box(Engine& e, const std::string& cmd) {
  if (!e.domain->box_exist) {
    throw InputError(cmd + " needs the simulation box; use create_box (or read_restart) first");
  }
}

/// Next free particle id: largest id anywhere + 1 (collective).
tagint next_id(Engine& e) {
  long long local = static_cast<long long>(e.particles->max_local_id()), all = 0;
  MPI_Allreduce(&local, &all, 1, MPI_LONG_LONG, MPI_MAX, e.world);
  return static_cast<tagint>(all + 1);
}

long long sum_all(Engine& e, long long local) {
  long long all = 0;
  MPI_Allreduce(&local, &all, 1, MPI_LONG_LONG, MPI_SUM, e.world);
  return all;
}

/// After particles were created or deleted: global count and id map.
void particles_changed(Engine& e) {
  e.particles->natoms = static_cast<tagint>(sum_all(e, e.particles->nlocal));
  e.particles->map_clear();
}

/// True when this rank owns a point that lies in the box: [sublo, subhi) per
/// dimension, the upper face of a non-periodic box belonging to the last rank.
bool owns_point(const Domain& dom, const Vec3& x) {
  for (int d = 0; d < 3; ++d) {
    if (x[d] < dom.sublo[d]) return false;
    if (x[d] >= dom.subhi[d]) {
      const bool upper_face = !dom.periodic[d] && dom.subhi[d] >= dom.boxhi[d] && x[d] <= dom.boxhi[d];
      if (!upper_face) return false;
    }
  }
  return true;
}

/// Uniform double in [0, 1) from a 64-bit generator (portable, unlike std distributions).
double uniform01(std::mt19937_64& gen) {
  return static_cast<double>(gen() >> 11) * 0x1.0p-53;
}

/// Uniform double in [0, 1) hashed from a seed and a particle id (rank-independent).
double hash01(long long seed, tagint id) {
  std::uint64_t z = static_cast<std::uint64_t>(seed) * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(id);
  for (int k = 0; k < 2; ++k) {  // two rounds of splitmix64
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
  }
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

int parse_type(Engine& e, const std::string& word, const std::string& what) {
  const long long t = parse_int(word, what);
  if (t < 1 || t > e.particles->ntypes) {
    throw InputError(what + " " + word + " is outside 1.." + std::to_string(e.particles->ntypes) +
                     " (the number of atom types given to create_box)");
  }
  return static_cast<int>(t);
}

bool parse_units_lattice(Engine& e, const std::string& word, const std::string& cmd) {
  if (word == "box") return false;
  if (word == "lattice") {
    if (e.domain->lattice_style == "none") {
      throw InputError(
          cmd + " units lattice needs a lattice; define one with the lattice command or use units box");
    }
    return true;
  }
  throw InputError(cmd + " units must be box or lattice, got '" + word + "'");
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// ---------------------------------------------------------------- lattice

void cmd_lattice(Engine& e, const Args& a) {
  const char* usage = "lattice none [SCALE] | lattice sc|bcc|fcc SCALE";
  require_args(a, 1, 2, usage);
  Domain& dom = *e.domain;
  const std::string& style = a[0];
  std::vector<Vec3> basis;
  if (style == "sc") {
    basis = {Vec3(0, 0, 0)};
  } else if (style == "bcc") {
    basis = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0.5)};
  } else if (style == "fcc") {
    basis = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 0.5), Vec3(0, 0.5, 0.5)};
  } else if (style != "none") {
    const std::vector<std::string> known = {"none", "sc", "bcc", "fcc"};
    const std::string hint = did_you_mean(style, known);
    throw InputError("unknown lattice style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + usage);
  }
  if (style != "none" && a.size() != 2) {
    throw InputError("lattice " + style + " needs the lattice constant; usage: " + usage);
  }
  const double scale = a.size() == 2 ? parse_double(a[1], "the lattice constant") : 1.0;
  if (!(scale > 0.0)) throw InputError("the lattice constant must be positive, got '" + a[1] + "'");
  dom.lattice_style = style;
  dom.lattice_basis = basis;
  for (double& s : dom.lattice_spacing)
    s = scale;
  if (style != "none") {
    e.logger->print("Lattice spacing in x,y,z = " + fmt(scale) + " " + fmt(scale) + " " + fmt(scale) + "\n");
  }
}

// ----------------------------------------------------------- create_atoms

constexpr double kDefaultDiameter = 1.0;  // LAMMPS/LIGGGHTS atom_style sphere defaults
constexpr double kDefaultDensity = 1.0;

void create_single(Engine& e, int type, const Args& a) {
  const char* usage = "create_atoms TYPE single X Y Z [units box|lattice] [remap yes|no]";
  if (a.size() < 5) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  bool lattice = false, remap = false;
  for (std::size_t k = 5; k < a.size(); k += 2) {
    if (k + 1 >= a.size()) throw InputError("create_atoms keyword '" + a[k] + "' needs a value");
    if (a[k] == "units") {
      lattice = parse_units_lattice(e, a[k + 1], "create_atoms");
    } else if (a[k] == "remap") {
      remap = parse_bool(a[k + 1], "create_atoms remap");
    } else {
      throw InputError("unknown create_atoms single keyword '" + a[k] + "'; usage: " + usage);
    }
  }
  Domain& dom = *e.domain;
  Vec3 x;
  for (int d = 0; d < 3; ++d) {
    x[d] = parse_double(a[2 + d], "create_atoms single coordinate");
    if (lattice) x[d] *= dom.lattice_spacing[d];
  }
  int image = Particles::image_pack(0, 0, 0);
  if (remap) dom.remap(x, image);
  if (!dom.inside_box(x)) {
    throw InputError("create_atoms single: the point (" + fmt(x[0]) + ", " + fmt(x[1]) + ", " + fmt(x[2]) +
                     ") lies outside the box" +
                     (remap ? "" : "; use remap yes to map it into a periodic box"));
  }
  image = Particles::image_pack(0, 0, 0);
  dom.remap(x, image);  // a point on the upper face of a periodic box belongs at the lower face
  for (int d = 0; d < 3; ++d)
    x[d] = std::max(x[d], dom.boxlo[d]);  // rounding in the wrap
  const tagint id = next_id(e);
  Particles& p = *e.particles;
  p.clear_ghosts();
  long long created = 0;
  if (owns_point(dom, x)) {
    const int i = p.add_local(id, type, x, 0.5 * kDefaultDiameter, kDefaultDensity);
    p.image[i] = image;
    created = 1;
  }
  created = sum_all(e, created);
  if (created != 1) {
    throw InputError("create_atoms single: the point was claimed by " + std::to_string(created) +
                     " ranks instead of one");
  }
  particles_changed(e);
  e.logger->print("Created 1 atoms\n");
}

void create_random(Engine& e, int type, const Args& a) {
  const char* usage =
      "create_atoms TYPE random N SEED REGION|NULL [overlap D] [maxtry N] [units box|lattice]";
  if (a.size() < 5) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  const long long n = parse_int(a[2], "create_atoms random count");
  const long long seed = parse_int(a[3], "create_atoms random seed");
  if (n < 0) throw InputError("create_atoms random needs a count >= 0");
  if (seed <= 0) throw InputError("create_atoms random needs a positive seed");
  Domain& dom = *e.domain;
  const Region* region = a[4] == "NULL" ? nullptr : dom.region_or_error(a[4], "create_atoms random");
  double overlap = 0.0;
  long long maxtry = 10;
  bool lattice = false;
  for (std::size_t k = 5; k < a.size(); k += 2) {
    if (k + 1 >= a.size()) throw InputError("create_atoms keyword '" + a[k] + "' needs a value");
    if (a[k] == "overlap") {
      overlap = parse_double(a[k + 1], "create_atoms overlap distance");
      if (!(overlap > 0.0)) throw InputError("create_atoms overlap distance must be positive");
    } else if (a[k] == "maxtry") {
      maxtry = parse_int(a[k + 1], "create_atoms maxtry");
      if (maxtry < 1) throw InputError("create_atoms maxtry must be at least 1");
    } else if (a[k] == "units") {
      lattice = parse_units_lattice(e, a[k + 1], "create_atoms");
    } else {
      throw InputError("unknown create_atoms random keyword '" + a[k] + "'; usage: " + usage);
    }
  }
  if (lattice) overlap *= dom.lattice_spacing[0];

  // sampling volume: the box, cut down to the region's bounds where it has any
  Vec3 lo = dom.boxlo, hi = dom.boxhi;
  Vec3 rlo, rhi;
  if (region && region->bounds(rlo, rhi)) {
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::max(lo[d], rlo[d]);
      hi[d] = std::min(hi[d], rhi[d]);
      if (lo[d] > hi[d]) {
        throw InputError("create_atoms random: region " + region->id + " does not overlap the box");
      }
    }
  }

  // existing particles, known to every rank, for the overlap test
  Particles& p = *e.particles;
  // points at least `overlap` apart: spheres of radius overlap/2 that must not overlap
  std::unique_ptr<SphereGrid> grid;
  if (overlap > 0.0) {
    grid = std::make_unique<SphereGrid>(dom, 0.5 * overlap);
    std::vector<double> mine;
    mine.reserve(3 * static_cast<std::size_t>(p.nlocal));
    for (int i = 0; i < p.nlocal; ++i)
      for (int d = 0; d < 3; ++d)
        mine.push_back(p.x[i][d]);
    std::vector<double> all = allgather(e.world, mine);
    for (std::size_t k = 0; k + 2 < all.size(); k += 3)
      grid->add(Vec3(all[k], all[k + 1], all[k + 2]), 0.5 * overlap);
  }

  // every rank draws the same points; each keeps those in its subdomain
  constexpr long long kMaxRegionMisses = 1000000;
  std::mt19937_64 gen(static_cast<std::uint64_t>(seed));
  const tagint base = next_id(e);
  p.clear_ghosts();
  long long inserted = 0;
  for (long long k = 0; k < n; ++k) {
    long long misses = 0, overlaps = 0;
    while (true) {
      Vec3 x;
      for (int d = 0; d < 3; ++d)
        x[d] = lo[d] + uniform01(gen) * (hi[d] - lo[d]);
      if (region && !region->match(x)) {
        if (++misses >= kMaxRegionMisses) {
          throw InputError("create_atoms random: no point of region " + region->id +
                           " found inside the box after " + std::to_string(kMaxRegionMisses) +
                           " tries; check the region");
        }
        continue;
      }
      if (grid && grid->overlaps(x, 0.5 * overlap)) {
        if (++overlaps >= maxtry) break;  // give up on this particle
        continue;
      }
      if (grid) grid->add(x, 0.5 * overlap);
      if (owns_point(dom, x)) p.add_local(base + inserted, type, x, 0.5 * kDefaultDiameter, kDefaultDensity);
      ++inserted;
      break;
    }
  }
  particles_changed(e);
  e.logger->print("Created " + std::to_string(inserted) + " atoms\n");
  if (inserted < n) {
    e.logger->warning("create_atoms random inserted only " + std::to_string(inserted) + " of " +
                      std::to_string(n) + " particles: the others overlapped after " +
                      std::to_string(maxtry) + " tries each (increase maxtry or lower the count)");
  }
}

void create_lattice(Engine& e, int type, const Args& a, bool use_region) {
  const std::size_t first = use_region ? 3 : 2;
  const char* usage = "create_atoms TYPE box|region REGION [basis M TYPE] ...";
  if (a.size() < first) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  Domain& dom = *e.domain;
  if (dom.lattice_style == "none" || dom.lattice_basis.empty()) {
    throw InputError("create_atoms " + a[1] +
                     " places particles on a lattice; define one with the lattice command first");
  }
  const Region* region = use_region ? dom.region_or_error(a[2], "create_atoms region") : nullptr;
  const int nbasis = static_cast<int>(dom.lattice_basis.size());
  std::vector<int> basis_type(nbasis, type);
  for (std::size_t k = first; k < a.size(); k += 3) {
    if (a[k] != "basis") throw InputError("unknown create_atoms keyword '" + a[k] + "'; usage: " + usage);
    if (k + 2 >= a.size()) throw InputError("create_atoms basis needs two values: M TYPE");
    const long long m = parse_int(a[k + 1], "create_atoms basis index");
    if (m < 1 || m > nbasis) {
      throw InputError("create_atoms basis index must be in 1.." + std::to_string(nbasis) + " for lattice " +
                       dom.lattice_style);
    }
    basis_type[m - 1] = parse_type(e, a[k + 2], "create_atoms basis type");
  }

  // lattice cells that can hold points of this rank's subdomain (and of the region)
  const double* sp = dom.lattice_spacing;
  Vec3 lo = dom.sublo, hi = dom.subhi;
  Vec3 rlo, rhi;
  if (region && region->bounds(rlo, rhi)) {
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::max(lo[d], rlo[d]);
      hi[d] = std::min(hi[d], rhi[d]);
    }
  }
  long long glo[3], gn[3], ilo[3], ihi[3];
  double ncand = nbasis;
  double nglobal = nbasis;
  for (int d = 0; d < 3; ++d) {
    glo[d] = static_cast<long long>(std::floor(dom.boxlo[d] / sp[d])) - 1;
    gn[d] = static_cast<long long>(std::ceil(dom.boxhi[d] / sp[d])) + 1 - glo[d] + 1;
    ilo[d] = static_cast<long long>(std::floor(lo[d] / sp[d])) - 1;
    ihi[d] = static_cast<long long>(std::ceil(hi[d] / sp[d])) + 1;
    ilo[d] = std::max(ilo[d], glo[d]);
    ihi[d] = std::min(ihi[d], glo[d] + gn[d] - 1);
    ncand *= static_cast<double>(std::max(0ll, ihi[d] - ilo[d] + 1));
    nglobal *= static_cast<double>(gn[d]);
  }
  double ncand_max = 0.0;
  MPI_Allreduce(&ncand, &ncand_max, 1, MPI_DOUBLE, MPI_MAX, e.world);
  if (nglobal > 4.0e18 || ncand_max > 2.0e9) {
    throw InputError("create_atoms: the lattice spacing " + fmt(sp[0]) +
                     " is far too small for the box (more than 2e9 lattice points per rank)");
  }

  // keys give every lattice point a global order, so ids do not depend on the rank count
  std::vector<long long> keys;
  std::vector<Vec3> pos;
  std::vector<int> types;
  for (long long k = ilo[2]; k <= ihi[2]; ++k) {
    for (long long j = ilo[1]; j <= ihi[1]; ++j) {
      for (long long i = ilo[0]; i <= ihi[0]; ++i) {
        for (int b = 0; b < nbasis; ++b) {
          const long long cellidx[3] = {i, j, k};
          Vec3 x;
          bool ok = true;
          for (int d = 0; d < 3 && ok; ++d) {
            x[d] = (static_cast<double>(cellidx[d]) + dom.lattice_basis[b][d]) * sp[d];
            const double eps = 1.0e-10 * dom.prd[d];
            if (x[d] < dom.boxlo[d] - eps)
              ok = false;
            else if (dom.periodic[d] && x[d] >= dom.boxhi[d] - eps)
              ok = false;  // the image at boxlo is made
            else if (!dom.periodic[d] && x[d] > dom.boxhi[d] + eps)
              ok = false;
            else
              x[d] = std::clamp(x[d], dom.boxlo[d], dom.boxhi[d]);
          }
          if (!ok || !owns_point(dom, x)) continue;
          if (region && !region->match(x)) continue;
          keys.push_back((((k - glo[2]) * gn[1] + (j - glo[1])) * gn[0] + (i - glo[0])) * nbasis + b);
          pos.push_back(x);
          types.push_back(basis_type[b]);
        }
      }
    }
  }

  // rank of each key among all created points
  std::vector<long long> all = allgather(e.world, keys);
  std::sort(all.begin(), all.end());

  const tagint base = next_id(e);
  Particles& p = *e.particles;
  p.clear_ghosts();
  for (std::size_t n = 0; n < keys.size(); ++n) {
    const auto rank = std::lower_bound(all.begin(), all.end(), keys[n]) - all.begin();
    p.add_local(base + rank, types[n], pos[n], 0.5 * kDefaultDiameter, kDefaultDensity);
  }
  particles_changed(e);
  e.logger->print("Created " + std::to_string(all.size()) + " atoms\n");
}

void cmd_create_atoms(Engine& e, const Args& a) {
  e.update->particles_changed();
  const char* usage =
      "create_atoms TYPE single X Y Z | random N SEED REGION | box | region REGION [keywords]";
  if (a.size() < 2) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  require_box(e, "create_atoms");
  const int type = parse_type(e, a[0], "create_atoms type");
  const std::string& style = a[1];
  if (style == "single") {
    create_single(e, type, a);
  } else if (style == "random") {
    create_random(e, type, a);
  } else if (style == "box") {
    create_lattice(e, type, a, false);
  } else if (style == "region") {
    if (a.size() < 3) throw InputError("create_atoms TYPE region needs a region ID");
    create_lattice(e, type, a, true);
  } else {
    const std::string hint = did_you_mean(style, {"single", "random", "box", "region"});
    throw InputError("unknown create_atoms style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + usage);
  }
}

// -------------------------------------------------------------------- set

/// Which particles a command acts on: set atom|type|group|region ID.
class Selection {
 public:
  Selection(Engine& e, const std::string& style, const std::string& id, const std::string& cmd) : e_(e) {
    if (style == "atom") {
      style_ = Atom;
      const auto star = id.find('*');
      if (star == std::string::npos) {
        lo_ = hi_ = parse_int(id, cmd + " atom ID");
      } else {
        const std::string a = id.substr(0, star), b = id.substr(star + 1);
        lo_ = a.empty() ? 1 : parse_int(a, cmd + " atom ID range");
        hi_ = b.empty() ? std::numeric_limits<long long>::max() : parse_int(b, cmd + " atom ID range");
      }
    } else if (style == "type") {
      style_ = Type;
      int lo, hi;
      parse_type_range(id, e.particles->ntypes, lo, hi);
      lo_ = lo;
      hi_ = hi;
    } else if (style == "group") {
      style_ = Group;
      bit_ = e.groups->bitmask(e.groups->find_or_error(id, cmd));
    } else if (style == "region") {
      style_ = RegionStyle;
      region_ = e.domain->region_or_error(id, cmd);
    } else {
      const std::string hint = did_you_mean(style, {"atom", "type", "group", "region"});
      throw InputError("unknown " + cmd + " style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; expected atom, type, group or region");
    }
  }

  bool selected(int i) const {
    const Particles& p = *e_.particles;
    switch (style_) {
      case Atom:
        return p.id[i] >= lo_ && p.id[i] <= hi_;
      case Type:
        return p.type[i] >= lo_ && p.type[i] <= hi_;
      case Group:
        return (p.mask[i] & bit_) != 0;
      case RegionStyle:
        return region_->match(p.x[i]);
    }
    return false;
  }

 private:
  enum Style { Atom, Type, Group, RegionStyle };
  Engine& e_;
  Style style_ = Group;
  long long lo_ = 0, hi_ = 0;
  int bit_ = 1;
  const Region* region_ = nullptr;
};

/// Name of the variable in "v_name", or "" for a plain value; the variable must exist.
std::string variable_ref(Engine& e, const std::string& word, const std::string& what) {
  if (word.rfind("v_", 0) != 0) return "";
  const std::string name = word.substr(2);
  if (!e.input->variables().find(name)) {
    throw InputError("unknown variable '" + name + "' in " + what +
                     "; define it with the variable command first");
  }
  return name;
}

void cmd_set(Engine& e, const Args& a) {
  e.update->particles_changed();
  const char* usage =
      "set atom|type|group|region ID keyword value ...  (keywords: type, type/fraction, diameter, density, "
      "mass, x, y, z, vx, vy, vz, omegax, omegay, omegaz, omega, image)";
  if (a.size() < 4) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  require_box(e, "set");
  const Selection sel(e, a[0], a[1], "set");
  Particles& p = *e.particles;

  // validate everything first so that a bad keyword changes nothing
  struct Setting {
    std::string key;
    std::vector<double> v;
    std::vector<std::string> var;  // per value: variable name or ""
    std::vector<bool> null;        // image components given as NULL
  };
  std::vector<Setting> settings;
  static const std::vector<std::string> keys = {
      "type", "type/fraction", "diameter", "density", "mass",  "x",    "y", "z", "vx", "vy",
      "vz",   "omegax",        "omegay",   "omegaz",  "omega", "image"};
  for (std::size_t k = 2; k < a.size();) {
    Setting s;
    s.key = a[k];
    std::size_t nval = 1;
    if (s.key == "omega" || s.key == "image" || s.key == "type/fraction") nval = 3;
    if (std::find(keys.begin(), keys.end(), s.key) == keys.end()) {
      const std::string hint = did_you_mean(s.key, keys);
      throw InputError("unknown set keyword '" + s.key + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + usage);
    }
    if (k + nval >= a.size()) {
      throw InputError("set " + s.key + " needs " + std::to_string(nval) + " value(s)");
    }
    for (std::size_t m = 1; m <= nval; ++m) {
      const std::string& w = a[k + m];
      s.var.push_back(variable_ref(e, w, "set " + s.key));
      s.null.push_back(s.key == "image" && w == "NULL");
      if (!s.var.back().empty()) {
        if (s.key == "type/fraction" || s.key == "image") {
          throw InputError("set " + s.key + " does not take variables; give numbers");
        }
        s.v.push_back(0.0);
      } else if (s.null.back()) {
        s.v.push_back(0.0);
      } else if (s.key == "type" || (s.key == "type/fraction" && m == 1)) {
        s.v.push_back(parse_type(e, w, "set type"));
      } else if (s.key == "image" || (s.key == "type/fraction" && m == 3)) {
        s.v.push_back(static_cast<double>(parse_int(w, "set " + s.key)));
      } else {
        s.v.push_back(parse_double(w, "set " + s.key));
      }
    }
    if ((s.key == "diameter" || s.key == "density" || s.key == "mass") && s.var[0].empty() &&
        !(s.v[0] > 0.0)) {
      throw InputError("set " + s.key + " must be positive, got '" + a[k + 1] + "'");
    }
    if (s.key == "type/fraction") {
      if (s.v[1] < 0.0 || s.v[1] > 1.0) throw InputError("set type/fraction needs a fraction in [0, 1]");
      if (s.v[2] <= 0.0) throw InputError("set type/fraction needs a positive seed");
    }
    settings.push_back(std::move(s));
    k += nval + 1;
  }

  e.logger->print("Setting atom values ...\n");
  for (const Setting& s : settings) {
    // per-atom values of variables, evaluated before this keyword changes anything
    std::vector<std::vector<double>> varvals(s.var.size());
    for (std::size_t c = 0; c < s.var.size(); ++c) {
      if (s.var[c].empty()) continue;
      e.input->variables().compute_atom(s.var[c], varvals[c]);
      varvals[c].resize(p.nlocal, 0.0);
    }
    auto value = [&](std::size_t c, int i) { return s.var[c].empty() ? s.v[c] : varvals[c][i]; };
    const std::string& key = s.key;
    bool any_var = false;
    for (const auto& v : s.var)
      any_var |= !v.empty();
    if (any_var) {
      // variable values are checked on every rank before anything is set
      long long bad = 0;
      for (int i = 0; i < p.nlocal; ++i) {
        if (!sel.selected(i)) continue;
        const double v = value(0, i);
        if (key == "type" && (static_cast<int>(v) < 1 || static_cast<int>(v) > p.ntypes)) ++bad;
        if ((key == "diameter" || key == "density" || key == "mass") && !(v > 0.0)) ++bad;
        for (std::size_t c = 0; c < s.var.size(); ++c)
          if (!std::isfinite(value(c, i))) ++bad;
      }
      bad = sum_all(e, bad);
      if (bad > 0) {
        throw InputError("set " + key + ": the variable gives " + std::to_string(bad) +
                         " invalid value(s) (types must be in 1.." + std::to_string(p.ntypes) +
                         ", sizes and masses positive)");
      }
    }
    long long count = 0;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!sel.selected(i)) continue;
      if (key == "type") {
        p.type[i] = static_cast<int>(value(0, i));
      } else if (key == "type/fraction") {
        if (hash01(static_cast<long long>(s.v[2]), p.id[i]) >= s.v[1]) continue;
        p.type[i] = static_cast<int>(s.v[0]);
      } else if (key == "diameter") {
        // as LIGGGHTS: the mass follows the new size at the particle's density
        p.radius[i] = 0.5 * value(0, i);
        if (p.density[i] > 0.0) p.rmass[i] = Particles::sphere_mass(p.radius[i], p.density[i]);
      } else if (key == "density") {
        p.density[i] = value(0, i);
        p.rmass[i] = p.radius[i] > 0.0 ? Particles::sphere_mass(p.radius[i], p.density[i]) : p.density[i];
      } else if (key == "mass") {
        p.rmass[i] = value(0, i);  // density is left alone (LIGGGHTS)
      } else if (key == "x" || key == "y" || key == "z") {
        p.x[i][key[0] - 'x'] = value(0, i);
      } else if (key == "vx" || key == "vy" || key == "vz") {
        p.v[i][key[1] - 'x'] = value(0, i);
      } else if (key == "omegax" || key == "omegay" || key == "omegaz") {
        p.omega[i][key[5] - 'x'] = value(0, i);
      } else if (key == "omega") {
        p.omega[i] = Vec3(value(0, i), value(1, i), value(2, i));
      } else if (key == "image") {
        int img[3];
        Particles::image_unpack(p.image[i], img[0], img[1], img[2]);
        for (int d = 0; d < 3; ++d)
          if (!s.null[d]) img[d] = static_cast<int>(s.v[d]);
        p.image[i] = Particles::image_pack(img[0], img[1], img[2]);
      }
      ++count;
    }
    count = sum_all(e, count);
    e.logger->print("  " + std::to_string(count) + " settings made for " + s.key + "\n");
  }
}

// --------------------------------------------------------------- velocity

void cmd_velocity(Engine& e, const Args& a) {
  e.update->particles_changed();
  const char* usage =
      "velocity GROUP set VX VY VZ | setAngular WX WY WZ | ramp vx|vy|vz VLO VHI x|y|z CLO CHI | "
      "zero linear|angular  [sum yes|no] [units box|lattice]";
  if (a.size() < 2) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  require_box(e, "velocity");
  const int igroup = e.groups->find_or_error(a[0], "velocity");
  const int bit = e.groups->bitmask(igroup);
  const std::string& style = a[1];
  std::size_t nargs = 0;
  if (style == "set" || style == "setAngular")
    nargs = 3;
  else if (style == "ramp")
    nargs = 6;
  else if (style == "zero")
    nargs = 1;
  else if (style == "create") {
    throw InputError("velocity create (thermal velocities) is not supported; use velocity set or ramp");
  } else {
    const std::string hint = did_you_mean(style, {"set", "setAngular", "ramp", "zero"});
    throw InputError("unknown velocity style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + usage);
  }
  if (a.size() < 2 + nargs)
    throw InputError("velocity " + style + " needs " + std::to_string(nargs) + " values; usage: " + usage);

  bool sum = false, lattice = false;
  for (std::size_t k = 2 + nargs; k < a.size(); k += 2) {
    if (k + 1 >= a.size()) throw InputError("velocity keyword '" + a[k] + "' needs a value");
    if (a[k] == "sum")
      sum = parse_bool(a[k + 1], "velocity sum");
    else if (a[k] == "units")
      lattice = parse_units_lattice(e, a[k + 1], "velocity");
    else if (a[k] == "dist" || a[k] == "mom" || a[k] == "rot" || a[k] == "loop")
      continue;  // used by create only
    else
      throw InputError("unknown velocity keyword '" + a[k] + "'; usage: " + usage);
  }
  const Domain& dom = *e.domain;
  Particles& p = *e.particles;
  const double* s = lattice ? dom.lattice_spacing : nullptr;

  if (style == "set" || style == "setAngular") {
    bool given[3];
    double val[3];
    std::vector<double> varvals[3];  // equal- or atom-style variables: one value per local particle
    for (int d = 0; d < 3; ++d) {
      const std::string& w = a[2 + d];
      given[d] = w != "NULL";
      const std::string var = variable_ref(e, w, "velocity " + style);
      if (!var.empty()) {
        e.input->variables().compute_atom(var, varvals[d]);
        varvals[d].resize(p.nlocal, 0.0);
        val[d] = 0.0;
      } else {
        val[d] = given[d] ? parse_double(w, "velocity " + style + " component") : 0.0;
      }
    }
    const double unit[3] = {s && style == "set" ? s[0] : 1.0, s && style == "set" ? s[1] : 1.0,
                            s && style == "set" ? s[2] : 1.0};
    std::vector<Vec3>& target = style == "set" ? p.v : p.omega;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & bit)) continue;
      for (int d = 0; d < 3; ++d) {
        if (!given[d]) continue;
        const double v = (varvals[d].empty() ? val[d] : varvals[d][i]) * unit[d];
        target[i][d] = sum ? target[i][d] + v : v;
      }
    }
    return;
  }

  if (style == "ramp") {
    auto vdim = [&](const std::string& w) {
      if (w == "vx") return 0;
      if (w == "vy") return 1;
      if (w == "vz") return 2;
      throw InputError("velocity ramp needs vx, vy or vz, got '" + w + "'");
    };
    auto cdim = [&](const std::string& w) {
      if (w == "x") return 0;
      if (w == "y") return 1;
      if (w == "z") return 2;
      throw InputError("velocity ramp needs x, y or z, got '" + w + "'");
    };
    const int vd = vdim(a[2]);
    double vlo = parse_double(a[3], "velocity ramp vlo"), vhi = parse_double(a[4], "velocity ramp vhi");
    const int cd = cdim(a[5]);
    double clo = parse_double(a[6], "velocity ramp clo"), chi = parse_double(a[7], "velocity ramp chi");
    if (s) {
      vlo *= s[vd];
      vhi *= s[vd];
      clo *= s[cd];
      chi *= s[cd];
    }
    if (!(chi > clo)) throw InputError("velocity ramp needs CLO < CHI");
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & bit)) continue;
      const double frac = std::clamp((p.x[i][cd] - clo) / (chi - clo), 0.0, 1.0);
      const double v = vlo + frac * (vhi - vlo);
      p.v[i][vd] = sum ? p.v[i][vd] + v : v;
    }
    return;
  }

  // zero linear|angular: remove the group's momentum / angular momentum about its centre of mass
  if (a[2] == "linear") {
    const Vec3 vcm = e.groups->vcm(igroup);
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & bit) p.v[i] -= vcm;
  } else if (a[2] == "angular") {
    const Vec3 xcm = e.groups->xcm(igroup);
    double local[12] = {0};  // L (3), inertia tensor (9)
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & bit)) continue;
      int ix, iy, iz;
      Particles::image_unpack(p.image[i], ix, iy, iz);
      const Vec3 r = p.x[i] + Vec3(ix * dom.prd[0], iy * dom.prd[1], iz * dom.prd[2]) - xcm;
      const double m = p.rmass[i];
      const Vec3 L = m * r.cross(p.v[i]);
      const Eigen::Matrix3d I = m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
      for (int d = 0; d < 3; ++d)
        local[d] += L[d];
      for (int q = 0; q < 9; ++q)
        local[3 + q] += I(q / 3, q % 3);
    }
    double all[12];
    MPI_Allreduce(local, all, 12, MPI_DOUBLE, MPI_SUM, e.world);
    const Vec3 L(all[0], all[1], all[2]);
    Eigen::Matrix3d I;
    for (int q = 0; q < 9; ++q)
      I(q / 3, q % 3) = all[3 + q];
    // omega = I^-1 L, restricted to the directions with inertia (a line of particles has none along it)
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
    const double lmax = eig.eigenvalues().maxCoeff();
    Vec3 omega = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      const double lam = eig.eigenvalues()[k];
      if (lam > 1.0e-12 * lmax && lam > 0.0) {
        const Vec3 ev = eig.eigenvectors().col(k);
        omega += ev * (ev.dot(L) / lam);
      }
    }
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & bit)) continue;
      int ix, iy, iz;
      Particles::image_unpack(p.image[i], ix, iy, iz);
      const Vec3 r = p.x[i] + Vec3(ix * dom.prd[0], iy * dom.prd[1], iz * dom.prd[2]) - xcm;
      p.v[i] -= omega.cross(r);
    }
  } else {
    throw InputError("velocity zero needs linear or angular, got '" + a[2] + "'");
  }
}

// ----------------------------------------------------------- delete_atoms

void cmd_delete_atoms(Engine& e, const Args& a) {
  e.update->particles_changed();
  const char* usage =
      "delete_atoms group GROUP | region REGION | porosity REGION FRACTION SEED  [compress yes|no] [mol "
      "yes|no]";
  if (a.size() < 2) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  require_box(e, "delete_atoms");
  Particles& p = *e.particles;
  const std::string& style = a[0];
  std::size_t first = 2;
  int bit = 0;
  const Region* region = nullptr;
  double fraction = 0.0;
  long long seed = 0;
  if (style == "group") {
    bit = e.groups->bitmask(e.groups->find_or_error(a[1], "delete_atoms"));
  } else if (style == "region") {
    region = e.domain->region_or_error(a[1], "delete_atoms");
  } else if (style == "porosity") {
    if (a.size() < 4)
      throw InputError(std::string("delete_atoms porosity needs REGION FRACTION SEED; usage: ") + usage);
    region = e.domain->region_or_error(a[1], "delete_atoms porosity");
    fraction = parse_double(a[2], "delete_atoms porosity fraction");
    seed = parse_int(a[3], "delete_atoms porosity seed");
    if (fraction < 0.0 || fraction > 1.0)
      throw InputError("delete_atoms porosity needs a fraction in [0, 1]");
    if (seed <= 0) throw InputError("delete_atoms porosity needs a positive seed");
    first = 4;
  } else if (style == "overlap") {
    throw InputError("delete_atoms overlap is not supported; use create_atoms random with overlap instead");
  } else {
    const std::string hint = did_you_mean(style, {"group", "region", "porosity"});
    throw InputError("unknown delete_atoms style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + usage);
  }
  bool compress = true, mol = false;
  for (std::size_t k = first; k < a.size(); k += 2) {
    if (k + 1 >= a.size()) throw InputError("delete_atoms keyword '" + a[k] + "' needs a value");
    if (a[k] == "compress")
      compress = parse_bool(a[k + 1], "delete_atoms compress");
    else if (a[k] == "mol")
      mol = parse_bool(a[k + 1], "delete_atoms mol");
    else
      throw InputError("unknown delete_atoms keyword '" + a[k] + "'; usage: " + usage);
  }

  const long long before = sum_all(e, p.nlocal);
  std::vector<char> doomed(p.nlocal, 0);
  std::vector<tagint> gone_bodies;
  for (int i = 0; i < p.nlocal; ++i) {
    if (style == "group")
      doomed[i] = (p.mask[i] & bit) != 0;
    else if (style == "region")
      doomed[i] = region->match(p.x[i]);
    else
      doomed[i] = region->match(p.x[i]) && hash01(seed, p.id[i]) < fraction;
  }
  if (mol) {
    // whole clumps go: every particle sharing a body id with a deleted one
    std::vector<long long> bodies;
    for (int i = 0; i < p.nlocal; ++i)
      if (doomed[i] && p.body[i] >= 0) bodies.push_back(static_cast<long long>(p.body[i]));
    std::vector<long long> all = allgather(e.world, bodies);
    const std::unordered_set<long long> gone(all.begin(), all.end());
    gone_bodies.assign(gone.begin(), gone.end());
    for (int i = 0; i < p.nlocal; ++i)
      if (p.body[i] >= 0 && gone.count(static_cast<long long>(p.body[i]))) doomed[i] = 1;
  }
  e.delete_particles(doomed);
  p.clear_ghosts();
  // whole clumps removed: their body records go too
  if (mol && !gone_bodies.empty())
    if (FixMultisphere* ms = FixMultisphere::find(*e.modify)) ms->remove_bodies(gone_bodies);

  {
    // surviving ids on every rank; with compress they become 1..N in the
    // order of the old ids (independent of the rank count)
    std::vector<long long> mine(p.nlocal);
    for (int i = 0; i < p.nlocal; ++i)
      mine[i] = static_cast<long long>(p.id[i]);
    std::vector<long long> all = allgather(e.world, mine);
    std::sort(all.begin(), all.end());
    // contact history between runs is keyed by ids: drop entries of deleted
    // particles (their ids may be used again) and follow the renumbering
    if (e.force->pair && e.force->pair->history()) e.force->pair->history()->retain(all, compress);
    if (compress) {
      for (int i = 0; i < p.nlocal; ++i) {
        p.id[i] = static_cast<tagint>(std::lower_bound(all.begin(), all.end(), mine[i]) - all.begin() + 1);
      }
    }
  }
  particles_changed(e);
  const long long after = static_cast<long long>(p.natoms);
  e.logger->print("Deleted " + std::to_string(before - after) +
                  " atoms, new total = " + std::to_string(after) + "\n");
}

}  // namespace

GRANARY_COMMAND("lattice", cmd_lattice);
GRANARY_COMMAND("create_atoms", cmd_create_atoms);
GRANARY_COMMAND("set", cmd_set);
GRANARY_COMMAND("velocity", cmd_velocity);
GRANARY_COMMAND("delete_atoms", cmd_delete_atoms);

}  // namespace granary
