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

}  // namespace granary
