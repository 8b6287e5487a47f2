// Resource checks before large allocations: a request that cannot fit is
// refused with an estimate instead of ending in std::bad_alloc or swapping.
#pragma once

#include <string>

namespace granary {

class Engine;

/// Bytes one particle costs on its rank: its fields, ghost copies, neighbour
/// list entries and contact history (tools/bench.py measures 3.9-4.1 kB on the
/// benchmarks; 4 kB is used).
constexpr double kBytesPerParticle = 4096.0;

/// Memory this machine can still give (MemAvailable of /proc/meminfo, else the
/// physical memory), in bytes; 0 when unknown.
double available_memory_bytes();

/// InputError when `n` more particles, spread evenly over the ranks, would need
/// more memory than this machine has available for its ranks (collective: every
/// rank gets the same verdict). `what` names the request, e.g. "create_atoms random".
void check_particle_memory(const Engine& e, double n, const std::string& what);

/// A cap on the particles of this process (all ranks together), checked by
/// check_particle_memory and create_atoms on a lattice; none by default. A
/// program that embeds the engine sets it (the fuzz targets keep random
/// scripts small with it).
void set_particle_limit(double n);
/// InputError when `n` more particles (an upper bound is fine) would pass the
/// cap set with set_particle_limit.
void check_particle_limit(const Engine& e, double n, const std::string& what);

}  // namespace granary
