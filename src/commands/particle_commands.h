// Helpers shared by the particle commands (commands/*.cpp): lattice,
// create_atoms, set, velocity, delete_atoms.
//
// Everything random in these commands is independent of the number of MPI
// ranks: random insertion draws the same sequence of points on every rank
// (each rank keeps the points in its subdomain), and per-particle random
// choices are hashed from the seed and the particle id.
#pragma once

#include <random>
#include <string>

#include "core/utils.h"
#include "core/vec3.h"
#include "particles/particles.h"

namespace granary {

class Engine;
class Domain;

namespace particle_commands {

/// InputError unless the simulation box exists.
void require_box(Engine& e, const std::string& cmd);
/// The start of a command that changes particles: tells Update that particles
/// changed, then InputError with the usage unless there are at least
/// `min_args` arguments, and unless the box exists.
void begin(Engine& e, const Args& a, std::size_t min_args, const std::string& cmd, const char* usage);
/// The next free particle id (collective).
tagint next_id(Engine& e);
/// InputError unless the group (bit) holds no spheres of clumps, which move
/// with their clump only: `cmd` moves particles one by one (collective).
void require_no_clump_spheres(Engine& e, int bit, const std::string& group, const std::string& cmd);
/// Sum over the ranks.
long long sum_all(Engine& e, long long local);
/// After particles were created or deleted: global count, map, and styles told.
void particles_changed(Engine& e);
/// Whether this rank's subdomain owns point x.
bool owns_point(const Domain& dom, const Vec3& x);
/// Uniform in [0, 1) from the generator.
double uniform01(std::mt19937_64& gen);
/// A uniform number in [0, 1) from a seed and a particle id (independent of the rank count).
double hash01(long long seed, tagint id);
/// An atom type word (1..ntypes).
int parse_type(Engine& e, const std::string& word, const std::string& what);
/// "units lattice|box" value: true for lattice.
bool parse_units_lattice(Engine& e, const std::string& word, const std::string& cmd);
/// A number for messages.
std::string fmt(double v);
/// Name of the variable in "v_name", or "" for a plain value; the variable must exist.
std::string variable_ref(Engine& e, const std::string& word, const std::string& what);

}  // namespace particle_commands
}  // namespace granary
