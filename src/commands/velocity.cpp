// The velocity command: set, ramp or create velocities and spins of a group.
#include <mpi.h>

#include <algorithm>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "particles/particles.h"

#include "commands/particle_commands.h"

namespace granary {

namespace {

using namespace particle_commands;

void cmd_velocity(Engine& e, const Args& a) {
  const char* usage =
      "velocity GROUP set VX VY VZ | setAngular WX WY WZ | ramp vx|vy|vz VLO VHI x|y|z CLO CHI | "
      "zero linear|angular  [sum yes|no] [units box|lattice]";
  begin(e, a, 2, "velocity", usage);
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
    const Vec3 omega = e.groups->omega(igroup, xcm);
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & bit) p.v[i] -= omega.cross(e.groups->unwrapped(i) - xcm);
  } else {
    throw InputError("velocity zero needs linear or angular, got '" + a[2] + "'");
  }
}

// ----------------------------------------------------------- delete_atoms

}  // namespace

GRANARY_COMMAND("velocity", cmd_velocity);

}  // namespace granary
