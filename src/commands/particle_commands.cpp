// Helpers shared by the particle commands (particle_commands.h).
#include <mpi.h>

#include <cstdint>
#include <cstdio>
#include <random>

#include "core/engine.h"
#include "core/update.h"
#include "core/error.h"
#include "core/input.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "particles/particles.h"

#include "commands/particle_commands.h"

namespace granary::particle_commands {

void require_box(Engine& e, const std::string& cmd) {
  if (!e.domain->box_exist) {
    throw InputError(cmd + " needs the simulation box; use create_box (or read_restart) first");
  }
}

void begin(Engine& e, const Args& a, std::size_t min_args, const std::string& cmd, const char* usage) {
  e.update->particles_changed();
  if (a.size() < min_args) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  require_box(e, cmd);
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

void require_no_clump_spheres(Engine& e, int bit, const std::string& group, const std::string& cmd) {
  const Particles& p = *e.particles;
  long long clump = 0;
  for (int i = 0; i < p.nlocal; ++i)
    if ((p.mask[i] & bit) && p.body[i] >= 0) ++clump;
  clump = sum_all(e, clump);
  if (clump > 0)
    throw InputError(
        cmd + ": group " + group + " holds " + std::to_string(clump) +
        " sphere(s) of clumps, which move with their clump only (fix multisphere); use a group of "
        "single spheres");
}

std::string fmt(double v) {
  return format_number(v);
}

// ---------------------------------------------------------------- lattice

// Name of the variable in "v_name", or "" for a plain value; the variable must exist.
std::string variable_ref(Engine& e, const std::string& word, const std::string& what) {
  if (word.rfind("v_", 0) != 0) return "";
  const std::string name = word.substr(2);
  if (!e.input->variables().find(name)) {
    throw InputError("unknown variable '" + name + "' in " + what +
                     "; define it with the variable command first");
  }
  return name;
}

}  // namespace granary::particle_commands
