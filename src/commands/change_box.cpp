// The change_box command: new bounds and boundary conditions of the
// (orthogonal) box between runs, with atom coordinates remapped on request
// (doc/commands/change_box.md).
#include <mpi.h>

#include <cmath>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "commands/particle_commands.h"
#include "particles/particles.h"

namespace granary {

namespace {

using namespace particle_commands;

const char* const kUsage =
    "change_box GROUP x|y|z final LO HI | delta DLO DHI | scale F | volume ... boundary X Y Z ... ortho ... "
    "set "
    "... remap ... [units lattice|box]";

int dim_of(const std::string& w) {
  return w == "x" ? 0 : w == "y" ? 1 : w == "z" ? 2 : -1;
}

void cmd_change_box(Engine& e, const Args& a) {
  begin(e, a, 2, "change_box", kUsage);
  const int bit = e.groups->bitmask(e.groups->find_or_error(a[0], "change_box"));
  Domain& dom = *e.domain;
  Particles& p = *e.particles;

  // a first pass: the words, the units (LAMMPS' default: lattice) and errors
  bool lattice = true, units_given = false, uses_distances = false;
  for (std::size_t k = 1; k < a.size();) {
    const std::string& w = a[k];
    if (dim_of(w) >= 0) {
      if (k + 1 >= a.size()) throw InputError("change_box " + w + " needs a style; usage: " + kUsage);
      const std::string& style = a[k + 1];
      const std::size_t n = style == "final" || style == "delta" ? 2
                            : style == "scale"                   ? 1
                            : style == "volume"                  ? 0
                                                                 : 99;
      if (n == 99)
        throw InputError("change_box " + w + " '" + style + "': expected final, delta, scale or volume");
      if (k + 2 + n > a.size())
        throw InputError("change_box " + w + " " + style + " needs " + std::to_string(n) +
                         " value(s); usage: " + kUsage);
      uses_distances |= style == "final" || style == "delta";
      k += 2 + n;
    } else if (w == "xy" || w == "xz" || w == "yz" || w == "triclinic") {
      throw InputError("change_box " + w +
                       ": triclinic (tilted) boxes are not supported; Granary's box is orthogonal");
    } else if (w == "boundary") {
      if (k + 4 > a.size())
        throw InputError("change_box boundary needs three values (X Y Z); usage: " + std::string(kUsage));
      k += 4;
    } else if (w == "ortho" || w == "set" || w == "remap") {
      k += 1;
    } else if (w == "units") {
      if (k + 1 >= a.size()) throw InputError("change_box units needs lattice or box");
      lattice = parse_units_lattice(e, a[k + 1], "change_box");
      units_given = true;
      k += 2;
    } else {
      throw InputError("change_box: unknown keyword '" + w + "'; usage: " + kUsage);
    }
  }
  if (uses_distances && lattice && !units_given && dom.lattice_style == "none")
    throw InputError(
        "change_box: distances are in lattice spacings by default (as in LAMMPS and LIGGGHTS) and no lattice "
        "is "
        "defined; add 'units box' for distances in box units");
  const Vec3 scale = lattice && dom.lattice_style != "none"
                         ? Vec3(dom.lattice_spacing[0], dom.lattice_spacing[1], dom.lattice_spacing[2])
                         : Vec3(1.0, 1.0, 1.0);

  // spheres of clumps move with their clump only: no remap of them
  bool remap = false;
  for (std::size_t k = 1; k < a.size(); ++k)
    remap |= a[k] == "remap";
  if (remap) require_no_clump_spheres(e, bit, a[0], "change_box remap");

  // the keywords in order, on a copy of the box
  Vec3 lo = dom.boxlo, hi = dom.boxhi;
  Vec3 saved_lo = lo, saved_hi = hi;
  auto boundary = dom.boundary;
  struct Remap {
    Vec3 from_lo, from_hi, to_lo, to_hi;
  };
  std::vector<Remap> remaps;
  const double volume0 = (hi - lo).prod();
  auto num = [&](std::size_t k, const std::string& what) { return parse_double(a[k], "change_box " + what); };
  for (std::size_t k = 1; k < a.size();) {
    const std::string& w = a[k];
    const int d = dim_of(w);
    if (d >= 0) {
      const std::string& style = a[k + 1];
      if (style == "final") {
        lo[d] = num(k + 2, w + " final LO") * scale[d];
        hi[d] = num(k + 3, w + " final HI") * scale[d];
        k += 4;
      } else if (style == "delta") {
        lo[d] += num(k + 2, w + " delta DLO") * scale[d];
        hi[d] += num(k + 3, w + " delta DHI") * scale[d];
        k += 4;
      } else if (style == "scale") {
        const double f = num(k + 2, w + " scale");
        if (!(f > 0.0)) throw InputError("change_box " + w + " scale must be positive, got " + a[k + 2]);
        const double mid = 0.5 * (lo[d] + hi[d]), half = 0.5 * f * (hi[d] - lo[d]);
        lo[d] = mid - half;
        hi[d] = mid + half;
        k += 3;
      } else {  // volume: this length keeps the volume the box had before the command
        double others = 1.0;
        for (int o = 0; o < 3; ++o)
          if (o != d) others *= hi[o] - lo[o];
        const double mid = 0.5 * (lo[d] + hi[d]), half = 0.5 * volume0 / others;
        lo[d] = mid - half;
        hi[d] = mid + half;
        k += 2;
      }
      if (!(hi[d] > lo[d]) || !std::isfinite(lo[d]) || !std::isfinite(hi[d]))
        throw InputError("change_box " + w + ": the box would be empty or not finite along " + w + " (" +
                         fmt(lo[d]) + " to " + fmt(hi[d]) + ")");
    } else if (w == "boundary") {
      for (int dim = 0; dim < 3; ++dim) {
        const std::string& b = a[k + 1 + dim];
        if (b.size() != 1 && b.size() != 2)
          throw InputError("change_box boundary '" + b + "' must be one or two of p f s m");
        const char blo = b[0], bhi = b.size() == 2 ? b[1] : b[0];
        for (char c : {blo, bhi})
          if (c != 'p' && c != 'f' && c != 's' && c != 'm')
            throw InputError("change_box boundary letter '" + std::string(1, c) + "' is not one of p f s m");
        if ((blo == 'p') != (bhi == 'p'))
          throw InputError("change_box boundary: a periodic boundary must be periodic on both sides");
        boundary[dim] = {blo, bhi};
      }
      k += 4;
    } else if (w == "set") {
      saved_lo = lo;
      saved_hi = hi;
      k += 1;
    } else if (w == "remap") {
      // the group's coordinates, from the box saved last (set, or the box
      // before the command) to the present one
      remaps.push_back({saved_lo, saved_hi, lo, hi});  // applied once every keyword is checked
      saved_lo = lo;
      saved_hi = hi;
      k += 1;
    } else if (w == "units") {
      k += 2;
    } else {  // ortho: the box is orthogonal already
      k += 1;
    }
  }

  // apply: the remaps in order, then the boundaries and the new box (also the
  // minimum of 'm' boundaries)
  for (const Remap& r : remaps)
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & bit)) continue;
      for (int dim = 0; dim < 3; ++dim)
        p.x[i][dim] = r.to_lo[dim] + (p.x[i][dim] - r.from_lo[dim]) / (r.from_hi[dim] - r.from_lo[dim]) *
                                         (r.to_hi[dim] - r.to_lo[dim]);
    }
  for (int dim = 0; dim < 3; ++dim) {
    const bool was_periodic = dom.periodic[dim];
    dom.boundary[dim] = boundary[dim];
    dom.periodic[dim] = boundary[dim][0] == 'p';
    if (was_periodic && !dom.periodic[dim]) {
      // image flags count crossings of a periodic box: none along a wall
      for (int i = 0; i < p.nlocal; ++i) {
        int im[3];
        Particles::image_unpack(p.image[i], im[0], im[1], im[2]);
        im[dim] = 0;
        p.image[i] = Particles::image_pack(im[0], im[1], im[2]);
      }
    }
  }
  dom.set_box(lo, hi);
  dom.reset_box();
  e.comm->setup(0.0);
  // the particles go to the ranks that own them at the next run's start
  e.logger->print("Changing box ...\n  orthogonal box = (" + fmt(dom.boxlo[0]) + " " + fmt(dom.boxlo[1]) +
                  " " + fmt(dom.boxlo[2]) + ") to (" + fmt(dom.boxhi[0]) + " " + fmt(dom.boxhi[1]) + " " +
                  fmt(dom.boxhi[2]) + ")\n");
}

}  // namespace

GRANARY_COMMAND("change_box", cmd_change_box);

}  // namespace granary
