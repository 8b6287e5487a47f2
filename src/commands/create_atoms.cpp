// The create_atoms command: single particles, random points in a region, lattice sites.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "comm/collectives.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/resources.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "geometry/sphere_grid.h"
#include "particles/particles.h"

#include "commands/particle_commands.h"

namespace granary {

namespace {

using namespace particle_commands;

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
  if (dom.dimension == 2 && x[2] != 0.0)
    throw InputError("create_atoms single: in 2d the z coordinate must be 0, got " + fmt(x[2]));
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
  check_particle_memory(e, static_cast<double>(n), "create_atoms random");
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
      if (dom.dimension == 2) x[2] = 0.0;  // 2d: the plane z = 0
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
    if (d == 2 && dom.dimension == 2) ilo[d] = ihi[d] = 0;  // 2d: the plane z = 0 only
    ncand *= static_cast<double>(std::max(0ll, ihi[d] - ilo[d] + 1));
    nglobal *= static_cast<double>(gn[d]);
  }
  double ncand_max = 0.0;
  MPI_Allreduce(&ncand, &ncand_max, 1, MPI_DOUBLE, MPI_MAX, e.world);
  if (nglobal > 4.0e18 || ncand_max > 2.0e9) {
    throw InputError("create_atoms: the lattice spacing " + fmt(sp[0]) +
                     " is far too small for the box (more than 2e9 lattice points per rank)");
  }
  double ncand_sum = 0.0;  // an upper bound of the points created
  MPI_Allreduce(&ncand, &ncand_sum, 1, MPI_DOUBLE, MPI_SUM, e.world);
  check_particle_limit(e, ncand_sum, "create_atoms on a lattice");

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
            else if (x[d] >= dom.boxhi[d] - eps)
              ok = false;  // periodic: the image at boxlo is made; fixed: as LIGGGHTS 3.8, none on the upper
                           // face
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
  const char* usage =
      "create_atoms TYPE single X Y Z | random N SEED REGION | box | region REGION [keywords]";
  begin(e, a, 2, "create_atoms", usage);
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

}  // namespace

GRANARY_COMMAND("create_atoms", cmd_create_atoms);

}  // namespace granary
