// The replicate command: the system copied nx x ny x nz times into a box that
// many times larger (doc/commands/replicate.md).
#include <mpi.h>

#include <cmath>
#include <string>

#include "comm/comm.h"
#include "commands/particle_commands.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "particles/particles.h"

namespace granary {

namespace {

using namespace particle_commands;

const char* const kUsage = "replicate NX NY NZ [offset OX OY OZ] [shift SX SY SZ]";

void cmd_replicate(Engine& e, const Args& a) {
  begin(e, a, 3, "replicate", kUsage);
  Domain& dom = *e.domain;
  Particles& p = *e.particles;
  int n[3];
  for (int d = 0; d < 3; ++d) {
    const long long v = parse_int(a[d], std::string("replicate ") + "XYZ"[d] + " factor");
    if (v < 1 || v > 1000000)
      throw InputError("replicate: the factor " + a[d] + " along " + "xyz"[d] + " must be an integer >= 1");
    n[d] = static_cast<int>(v);
  }
  // LIGGGHTS 3.8 reads offset and shift and replicates at the box length,
  // unshifted, whatever they say: Granary does the same and refuses values
  // that would mean something else
  for (std::size_t k = 3; k < a.size(); k += 4) {
    if ((a[k] != "offset" && a[k] != "shift") || k + 3 >= a.size())
      throw InputError("replicate: unknown keyword or missing values at '" + a[k] + "'; usage: " + kUsage);
    for (int d = 0; d < 3; ++d) {
      const double v = parse_double(a[k + 1 + d], "replicate " + a[k]);
      if (a[k] == "offset" && std::abs(v - dom.prd[d]) > 1e-9 * dom.prd[d])
        throw InputError("replicate offset: " + a[k + 1 + d] + " along " + "xyz"[d] +
                         " is not the box length " + fmt(dom.prd[d]) +
                         "; the copies are placed one box length apart (as LIGGGHTS 3.8 does whatever offset "
                         "says)");
      if (a[k] == "shift" && v != 0.0)
        throw InputError("replicate shift: " + a[k + 1 + d] +
                         " is not 0; shift the particles with displace_atoms after replicate (LIGGGHTS 3.8 "
                         "ignores shift)");
    }
  }
  long long clump = 0;
  for (int i = 0; i < p.nlocal; ++i)
    if (p.body[i] >= 0) ++clump;
  if (sum_all(e, clump) > 0 || e.modify->find_fix_by_style("multisphere"))
    throw InputError(
        "replicate: clumps (fix multisphere) cannot be replicated; replicate a system of single "
        "spheres, or insert the larger system");
  const tagint maxtag = next_id(e) - 1;
  const long long copies = static_cast<long long>(n[0]) * n[1] * n[2];
  if (copies > 1000000000LL || copies * static_cast<long long>(p.natoms) > 2000000000LL ||
      copies * maxtag > (1LL << 53))
    throw InputError("replicate: " + std::to_string(copies) + " copies of " + std::to_string(p.natoms) +
                     " particles are too many");

  // every particle where it is in the box (as LIGGGHTS 3.8: a periodic
  // system tiles the larger box the same way unwrapped or not), image flags
  // reset to 0; copy k = (ix ny + iy) nz + iz (z fastest) takes the ids
  // id + k * maxtag
  const Vec3 length = dom.prd;
  p.clear_ghosts();
  const int n0 = p.nlocal;
  p.resize(static_cast<int>(n0 * copies));
  p.nlocal = static_cast<int>(n0 * copies);
  for (int i = 0; i < n0; ++i)
    p.image[i] = Particles::image_pack(0, 0, 0);
  for (int ix = 0; ix < (n0 > 0 ? n[0] : 0); ++ix)
    for (int iy = 0; iy < n[1]; ++iy)
      for (int iz = 0; iz < n[2]; ++iz) {
        const long long k = (static_cast<long long>(ix) * n[1] + iy) * n[2] + iz;
        if (k == 0) continue;
        const Vec3 shift(ix * length[0], iy * length[1], iz * length[2]);
        for (int i = 0; i < n0; ++i) {
          const int j = static_cast<int>(k * n0 + i);
          p.copy(i, j);
          p.id[j] = p.id[i] + static_cast<tagint>(k) * maxtag;
          p.x[j] += shift;
        }
      }
  Vec3 hi;
  for (int d = 0; d < 3; ++d)
    hi[d] = dom.boxlo[d] + n[d] * length[d];
  dom.set_box(dom.boxlo, hi);
  for (int i = 0; i < p.nlocal; ++i)
    dom.remap(p.x[i], p.image[i]);
  particles_changed(e);
  dom.reset_box();
  e.comm->setup(0.0);
  // the particles go to the ranks that own them at the next run's start
  e.logger->print("Replicating atoms ...\n  orthogonal box = (" + fmt(dom.boxlo[0]) + " " +
                  fmt(dom.boxlo[1]) + " " + fmt(dom.boxlo[2]) + ") to (" + fmt(dom.boxhi[0]) + " " +
                  fmt(dom.boxhi[1]) + " " + fmt(dom.boxhi[2]) + ")\n  " + std::to_string(p.natoms) +
                  " atoms\n");
}

}  // namespace

GRANARY_COMMAND("replicate", cmd_replicate);

}  // namespace granary
