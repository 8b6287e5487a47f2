#include "core/resources.h"

#include <mpi.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/engine.h"
#include "core/error.h"
#include "particles/particles.h"

namespace granary {

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kb = 0.0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024.0;
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

namespace {
double g_particle_limit = -1.0;  // < 0: none
}  // namespace

void set_particle_limit(double n) {
  g_particle_limit = n;
}

void check_particle_limit(const Engine& e, double n, const std::string& what) {
  if (g_particle_limit < 0.0) return;
  const double total = n + static_cast<double>(e.particles->natoms);
  if (!(total <= g_particle_limit)) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s: %.4g particles would pass this program's limit of %.4g particles",
                  what.c_str(), total, g_particle_limit);
    throw InputError(buf);
  }
}

void check_particle_memory(const Engine& e, double n, const std::string& what) {
  check_particle_limit(e, n, what);
  const double avail = available_memory_bytes();
  if (!(avail > 0.0) || !(n > 0.0)) return;
  // the particles spread over the ranks; the ranks of this machine share its memory
  MPI_Comm node;
  MPI_Comm_split_type(e.world, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int on_node = 1;
  MPI_Comm_size(node, &on_node);
  MPI_Comm_free(&node);
  const double share = static_cast<double>(on_node) / static_cast<double>(e.nprocs);
  const double total = (n + static_cast<double>(e.particles->natoms)) * kBytesPerParticle * share;
  int refuse = total > avail ? 1 : 0, any = 0;  // one verdict for every rank
  MPI_Allreduce(&refuse, &any, 1, MPI_INT, MPI_MAX, e.world);
  if (!any) return;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s: %.4g particles would need about %.3g GB on this machine (%.0f kB per particle with "
                "its neighbour list and contact history, %.4g particles there already, %d of %d ranks "
                "here), more than the %.3g GB it has available; ask for fewer particles, or run on "
                "more machines",
                what.c_str(), n, total / 1e9, kBytesPerParticle / 1024.0,
                static_cast<double>(e.particles->natoms), on_node, e.nprocs, avail / 1e9);
  throw InputError(buf);
}

}  // namespace granary
