// The displace_atoms command (LAMMPS/LIGGGHTS): move a group of particles by
// a displacement (move), a displacement that depends on a coordinate (ramp),
// a random displacement (random; the same for a particle on any number of
// ranks) or a rotation about an axis (rotate). Positions are mapped back into
// periodic boxes at once (image flags count the crossings); a particle that
// leaves its rank's subdomain moves to its new owner when the next run starts.
#include <algorithm>
#include <cmath>
#include <functional>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "particles/particles.h"

#include "commands/particle_commands.h"

namespace granary {

namespace {

using namespace particle_commands;

int parse_dim(const std::string& w, const std::string& what) {
  if (w == "x") return 0;
  if (w == "y") return 1;
  if (w == "z") return 2;
  throw InputError(what + " must be x, y or z, got '" + w + "'");
}

void cmd_displace_atoms(Engine& e, const Args& a) {
  const char* usage =
      "displace_atoms GROUP move DX DY DZ | ramp x|y|z DLO DHI x|y|z CLO CHI | random DX DY DZ SEED | "
      "rotate PX PY PZ RX RY RZ THETA  [units box|lattice]";
  begin(e, a, 2, "displace_atoms", usage);
  const int bit = e.groups->bitmask(e.groups->find_or_error(a[0], "displace_atoms"));
  const std::string& style = a[1];
  std::size_t nargs = 0;
  if (style == "move")
    nargs = 3;
  else if (style == "ramp")
    nargs = 6;
  else if (style == "random")
    nargs = 4;
  else if (style == "rotate")
    nargs = 7;
  else {
    const std::string hint = did_you_mean(style, {"move", "ramp", "random", "rotate"});
    throw InputError("unknown displace_atoms style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + usage);
  }
  bool short_of_values = a.size() < 2 + nargs;
  for (std::size_t k = 2; k < 2 + nargs && k < a.size(); ++k)
    short_of_values |= a[k] == "units";
  if (short_of_values)
    throw InputError("displace_atoms " + style + " needs " + std::to_string(nargs) +
                     " values; usage: " + usage);
  // LAMMPS' default: units lattice
  bool lattice = true;
  bool units_given = false;
  for (std::size_t k = 2 + nargs; k < a.size(); k += 2) {
    if (a[k] != "units" || k + 1 >= a.size())
      throw InputError("displace_atoms: unknown keyword '" + a[k] +
                       "' (only units box|lattice); usage: " + usage);
    lattice = parse_units_lattice(e, a[k + 1], "displace_atoms");
    units_given = true;
  }
  Domain& dom = *e.domain;
  if (lattice && !units_given && dom.lattice_style == "none")
    throw InputError(
        "displace_atoms: distances are in lattice spacings by default (as in LAMMPS and LIGGGHTS) and no "
        "lattice is defined; add 'units box' for distances in box units");
  const Vec3 scale = lattice ? Vec3(dom.lattice_spacing[0], dom.lattice_spacing[1], dom.lattice_spacing[2])
                             : Vec3(1.0, 1.0, 1.0);
  auto num = [&](std::size_t k, const char* what) {
    return parse_double(a[2 + k], "displace_atoms " + style + " " + what);
  };

  Particles& p = *e.particles;
  require_no_clump_spheres(e, bit, a[0], "displace_atoms");

  std::function<void(int)> displace;
  Vec3 d, pt, axis;
  int ddim = 0, cdim = 0;
  double lo = 0, hi = 0, clo = 0, chi = 0, theta = 0;
  long long seed = 0;
  if (style == "move") {
    d = Vec3(num(0, "DX") * scale[0], num(1, "DY") * scale[1], num(2, "DZ") * scale[2]);
    displace = [&](int i) { p.x[i] += d; };
  } else if (style == "ramp") {
    ddim = parse_dim(a[2], "displace_atoms ramp: the displaced dimension");
    lo = num(1, "DLO") * scale[ddim];
    hi = num(2, "DHI") * scale[ddim];
    cdim = parse_dim(a[5], "displace_atoms ramp: the coordinate dimension");
    clo = num(4, "CLO") * scale[cdim];
    chi = num(5, "CHI") * scale[cdim];
    if (!(chi > clo)) throw InputError("displace_atoms ramp: CHI must be larger than CLO");
    displace = [&](int i) {
      const double f = std::min(1.0, std::max(0.0, (p.x[i][cdim] - clo) / (chi - clo)));
      p.x[i][ddim] += lo + f * (hi - lo);
    };
  } else if (style == "random") {
    d = Vec3(num(0, "DX") * scale[0], num(1, "DY") * scale[1], num(2, "DZ") * scale[2]);
    seed = parse_int(a[5], "displace_atoms random seed");
    if (seed <= 0) throw InputError("displace_atoms random: the seed must be a positive integer");
    // one independent number per particle and dimension, from the seed and the id
    displace = [&](int i) {
      for (int k = 0; k < 3; ++k)
        p.x[i][k] += d[k] * (2.0 * hash01(seed, 3 * p.id[i] + k) - 1.0);
    };
  } else {
    pt = Vec3(num(0, "PX") * scale[0], num(1, "PY") * scale[1], num(2, "PZ") * scale[2]);
    axis = Vec3(num(3, "RX"), num(4, "RY"), num(5, "RZ"));
    if (!(axis.norm() > 0.0)) throw InputError("displace_atoms rotate: the axis (RX RY RZ) must not be zero");
    axis.normalize();
    theta = num(6, "THETA") * M_PI / 180.0;
    displace = [&](int i) {
      // Rodrigues' rotation of the arm from the axis point
      const Vec3 r = p.x[i] - pt;
      const double c = std::cos(theta), s = std::sin(theta);
      p.x[i] = pt + r * c + axis.cross(r) * s + axis * (axis.dot(r) * (1.0 - c));
    };
  }
  e.logger->print("Displacing atoms ...\n");
  long long moved = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & bit)) continue;
    displace(i);
    dom.remap(p.x[i], p.image[i]);
    ++moved;
  }
  moved = sum_all(e, moved);
  e.logger->print("  " + std::to_string(moved) + " particles displaced\n");
}

}  // namespace

GRANARY_COMMAND("displace_atoms", cmd_displace_atoms);

}  // namespace granary
