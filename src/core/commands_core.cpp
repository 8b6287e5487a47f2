// Core setup commands: units, atom_style, atom_modify, boundary, newton,
// dimension, create_box, region, fix/unfix, compute/uncompute, compute_modify,
// pair_style, pair_coeff.
#include <algorithm>

#include "comm/comm.h"
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/style_list.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "core/modify.h"
#include "fix/fix.h"
#include "neighbor/neighbor.h"
#include "core/force.h"
#include "pair/pair.h"
#include "particles/particles.h"

namespace granary {

const std::vector<std::string>& atom_style_names() {
  // Spheres with radius, density, mass, angular velocity and torque: LIGGGHTS'
  // granular style and its alias sphere.
  // sph: point particles of smoothed particle hydrodynamics (doc/commands/atom_style.md).
  static const std::vector<std::string> names = {"granular", "sphere", "sph"};
  return names;
}

namespace {

void require_no_box(Engine& e, const std::string& cmd) {
  if (e.domain->box_exist)
    throw InputError(cmd + " must come before the box is created (create_box or read_restart)");
}
void require_box(Engine& e, const std::string& cmd) {
  if (!e.domain->box_exist) throw InputError(cmd + " needs the box: use create_box or read_restart first");
}

void cmd_units(Engine& e, const Args& a) {
  require_args(a, 1, 1, "units si|cgs");
  require_no_box(e, "units");
  if (a[0] != "si" && a[0] != "cgs") {
    throw InputError("units '" + a[0] + "' is not supported; granular scripts use si (or cgs)");
  }
  e.domain->units = a[0];
  if (a[0] == "cgs") e.neighbor->skin = 0.1;  // 1 mm as for si
}

void cmd_atom_style(Engine& e, const Args& a) {
  require_args(a, 1, 100, "atom_style granular|sphere|sph");
  require_no_box(e, "atom_style");
  const auto& names = atom_style_names();
  if (std::find(names.begin(), names.end(), a[0]) == names.end()) {
    throw InputError("atom_style '" + a[0] + "' is not supported; use granular (or sphere), or sph");
  }
  if (a[0] == "sph" && a.size() > 1)
    throw InputError("atom_style sph takes no arguments, got '" + a[1] + "'");
  e.particles->set_sph(a[0] == "sph");
}

// mass I value: the per-type mass of atom_style sph (LAMMPS' per-type masses);
// granular particles take their mass from diameter and density.
void cmd_mass(Engine& e, const Args& a) {
  require_args(a, 2, 2, "mass I value   (I: a type or a range like * or 1*2)");
  require_box(e, "mass");
  Particles& p = *e.particles;
  if (!p.sph)
    throw InputError(
        "mass sets per-type masses, which only atom_style sph has: granular particles take their "
        "mass from their diameter and density (set density, or the particle template)");
  int lo = 0, hi = 0;
  parse_type_range(a[0], p.ntypes, lo, hi);
  const double m = parse_double(a[1], "mass value");
  if (!(m > 0.0)) throw InputError("mass must be positive, got '" + a[1] + "'");
  if (static_cast<int>(p.type_mass.size()) <= p.ntypes) p.type_mass.resize(p.ntypes + 1, 0.0);
  for (int t = lo; t <= hi; ++t)
    p.type_mass[t] = m;
  for (int i = 0; i < p.nlocal; ++i)
    if (p.type[i] >= lo && p.type[i] <= hi) p.rmass[i] = m;
}

void cmd_atom_modify(Engine& e, const Args& a) {
  if (a.empty()) throw InputError("usage: atom_modify map array|hash | sort N BINSIZE | first G");
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k] == "map" && k + 1 < a.size()) {
      ++k;  // the id map is always an array here
    } else if (a[k] == "sort" && k + 2 < a.size()) {
      e.neighbor->sort_every = static_cast<int>(parse_int(a[k + 1], "atom_modify sort"));
      e.neighbor->sort_binsize = parse_double(a[k + 2], "atom_modify sort binsize");
      k += 2;
    } else if (a[k] == "first" && k + 1 < a.size()) {
      ++k;
    } else if (a[k] == "map" || a[k] == "sort" || a[k] == "first") {
      throw InputError("atom_modify " + a[k] + " needs " +
                       (a[k] == "sort" ? "two values: sort N BINSIZE" : "a value"));
    } else {
      throw InputError("unknown atom_modify keyword '" + a[k] + "'; expected map, sort or first");
    }
  }
}

void cmd_boundary(Engine& e, const Args& a) {
  require_args(a, 3, 3, "boundary X Y Z   (each p, f, s, m or a pair like fm)");
  require_no_box(e, "boundary");
  Domain& d = *e.domain;
  for (int dim = 0; dim < 3; ++dim) {
    const std::string& w = a[dim];
    if (w.size() != 1 && w.size() != 2)
      throw InputError("boundary '" + w + "' must be one or two of p f s m");
    const char lo = w[0], hi = w.size() == 2 ? w[1] : w[0];
    for (char c : {lo, hi}) {
      if (c != 'p' && c != 'f' && c != 's' && c != 'm') {
        throw InputError("boundary letter '" + std::string(1, c) + "' is not one of p f s m");
      }
    }
    if ((lo == 'p') != (hi == 'p')) throw InputError("a periodic boundary must be periodic on both sides");
    d.boundary[dim] = {lo, hi};
    d.periodic[dim] = lo == 'p';
  }
}

void cmd_newton(Engine& e, const Args& a) {
  require_args(a, 1, 2, "newton on|off [on|off]");
  // "newton on|off" or "newton PAIR BOND": only the pair setting matters here
  e.force->newton_pair = parse_bool(a[0], "newton");
  if (a.size() == 2) parse_bool(a[1], "newton bond setting");
}

// LIGGGHTS refuses youngsModulus below 5e6 (si) unless "soft_particles yes"
// and above 1e9 unless "hard_particles yes". Granary has no such limits (the
// timestep checks catch a stiffness the timestep cannot resolve), so both
// commands are accepted for LIGGGHTS scripts and change nothing.
void cmd_particle_stiffness_limit(const std::string& cmd, const Args& a) {
  require_args(a, 1, 1, cmd + " yes|no");
  parse_bool(a[0], cmd);
}
void cmd_soft_particles(Engine&, const Args& a) {
  cmd_particle_stiffness_limit("soft_particles", a);
}
void cmd_hard_particles(Engine&, const Args& a) {
  cmd_particle_stiffness_limit("hard_particles", a);
}

// dimension 2: particles in the xy plane (fix enforce2d keeps them there), the
// box periodic in z around z = 0, no ghosts along z (doc/commands/dimension.md)
void cmd_dimension(Engine& e, const Args& a) {
  require_args(a, 1, 1, "dimension 2|3");
  require_no_box(e, "dimension");
  if (a[0] != "2" && a[0] != "3") throw InputError("dimension must be 2 or 3, got '" + a[0] + "'");
  e.domain->dimension = a[0] == "2" ? 2 : 3;
}

void cmd_create_box(Engine& e, const Args& a) {
  require_args(a, 2, 100, "create_box NTYPES REGION-ID");
  require_no_box(e, "create_box");
  const long long ntypes = parse_int(a[0], "create_box number of types");
  if (ntypes < 1) throw InputError("create_box needs at least one atom type");
  if (ntypes > Particles::kMaxTypes) {
    throw InputError("create_box: " + std::to_string(ntypes) + " atom types are more than the " +
                     std::to_string(Particles::kMaxTypes) + " Granary supports");
  }
  Region* r = e.domain->region_or_error(a[1], "create_box");
  Vec3 lo, hi;
  if (!r->bounds(lo, hi))
    throw InputError("create_box needs a bounded region; '" + a[1] + "' has no finite bounds");
  if (e.domain->dimension == 2 && (!e.domain->periodic[2] || !(lo[2] < 0.0 && hi[2] > 0.0)))
    throw InputError(
        "dimension 2 needs a box periodic in z (boundary X Y p) whose z range holds z = 0, e.g. "
        "-0.001 0.001; region " +
        a[1] + " spans z " + std::to_string(lo[2]) + " to " + std::to_string(hi[2]));
  e.domain->set_box(lo, hi);
  e.particles->ntypes = static_cast<int>(ntypes);
  e.comm->setup(0.0);
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "Created box = (%g %g %g) to (%g %g %g)\n  %d by %d by %d MPI processor grid\n", lo[0], lo[1],
                lo[2], hi[0], hi[1], hi[2], e.comm->procgrid[0], e.comm->procgrid[1], e.comm->procgrid[2]);
  e.logger->print(buf);
}

void cmd_region(Engine& e, const Args& a) {
  e.domain->add_region(a);
}

void cmd_fix(Engine& e, const Args& a) {
  require_box(e, "fix");
  e.modify->add_fix(a);
}
void cmd_unfix(Engine& e, const Args& a) {
  require_args(a, 1, 1, "unfix ID");
  e.modify->delete_fix(a[0]);
}
void cmd_fix_modify(Engine& e, const Args& a) {
  const char* usage = "fix_modify FIX-ID keyword value ...";
  require_args(a, 2, 1000, usage);
  Fix* f = e.modify->fix_or_error(a[0], "fix_modify");
  for (std::size_t k = 1; k < a.size();) {
    const std::size_t used = f->modify_param(a, k);
    if (used > 0) {
      k += used;
      continue;
    }
    const std::string& w = a[k];
    if (w == "energy" || w == "virial") {
      if (k + 1 >= a.size()) throw InputError("fix_modify " + w + " needs yes or no");
      if (parse_bool(a[k + 1], "fix_modify " + w))
        throw InputError(
            "fix_modify " + a[0] + " " + w + " yes: fix " + f->style +
            " contributes no potential energy or virial (granular contacts have none in Granary)");
      k += 2;
    } else if (w == "temp" || w == "press") {
      throw InputError("fix_modify " + w + ": Granary has no temperature or pressure computes to give a fix");
    } else {
      throw InputError("fix_modify: fix " + a[0] + " (" + f->style + ") has no keyword '" + w +
                       "'; the keywords of fix_modify are energy, virial and those of the fix's own page");
    }
  }
}
void cmd_compute(Engine& e, const Args& a) {
  require_box(e, "compute");
  e.modify->add_compute(a);
}
void cmd_uncompute(Engine& e, const Args& a) {
  require_args(a, 1, 1, "uncompute ID");
  e.modify->delete_compute(a[0]);
}
void cmd_compute_modify(Engine& e, const Args& a) {
  require_args(a, 3, 100, "compute_modify ID keyword value ...");
  // LIGGGHTS scripts set "compute_modify thermo_temp dynamic yes": the particle
  // count is always current here, so the built-in thermo computes accept it.
  if (a[0] == "thermo_temp" || a[0] == "thermo_press") return;
  Compute* c = e.modify->compute_or_error(a[0], "compute_modify");
  for (std::size_t k = 1; k + 1 < a.size(); k += 2) {
    if (a[k] == "dynamic" || a[k] == "dynamic/dof" || a[k] == "extra" || a[k] == "extra/dof") continue;
    throw InputError("unknown compute_modify keyword '" + a[k] + "' for compute " + c->id);
  }
}

void cmd_pair_style(Engine& e, const Args& a) {
  e.force->create_pair(a);
}
void cmd_pair_coeff(Engine& e, const Args& a) {
  require_box(e, "pair_coeff");
  if (!e.force->pair) throw InputError("pair_coeff needs a pair style: use pair_style first");
  e.force->pair->coeff(a);
}

// run_style verlet: the one time integrator (velocity Verlet), as LIGGGHTS'
// default; rRESPA (multiple timestepping) is not available.
void cmd_run_style(Engine&, const Args& a) {
  if (a.empty()) throw InputError("run_style needs a style; usage: run_style verlet");
  if (a[0] != "verlet")
    throw InputError("run_style " + a[0] +
                     " is not available: Granary integrates with velocity Verlet only; use "
                     "run_style verlet or leave the command out");
  if (a.size() > 1) throw InputError("run_style verlet takes no arguments");
}

}  // namespace

GRANARY_COMMAND("run_style", cmd_run_style);
GRANARY_COMMAND("units", cmd_units);
GRANARY_COMMAND("atom_style", cmd_atom_style);
GRANARY_COMMAND("atom_modify", cmd_atom_modify);
GRANARY_COMMAND("boundary", cmd_boundary);
GRANARY_COMMAND("newton", cmd_newton);
GRANARY_COMMAND("dimension", cmd_dimension);
GRANARY_COMMAND("mass", cmd_mass);
GRANARY_COMMAND("soft_particles", cmd_soft_particles);
GRANARY_COMMAND("hard_particles", cmd_hard_particles);
GRANARY_COMMAND("create_box", cmd_create_box);
GRANARY_COMMAND("region", cmd_region);
GRANARY_COMMAND("fix", cmd_fix);
GRANARY_COMMAND("unfix", cmd_unfix);
GRANARY_COMMAND("fix_modify", cmd_fix_modify);
GRANARY_COMMAND("compute", cmd_compute);
GRANARY_COMMAND("uncompute", cmd_uncompute);
GRANARY_COMMAND("compute_modify", cmd_compute_modify);
GRANARY_COMMAND("pair_style", cmd_pair_style);
GRANARY_COMMAND("pair_coeff", cmd_pair_coeff);

}  // namespace granary
