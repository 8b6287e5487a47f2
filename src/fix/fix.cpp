#include "fix/fix.h"

#include <mpi.h>

#include <cctype>

#include "core/engine.h"
#include "core/error.h"
#include "domain/groups.h"
#include "particles/particles.h"

namespace granary {

namespace {
void check_id(const std::string& id, const std::string& kind) {
  for (char c : id) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) {
      throw InputError(kind + " ID '" + id + "' may use only letters, digits and underscores");
    }
  }
}
}  // namespace

Fix::Fix(Engine& engine, const Args& args) : engine_(engine), args_(args) {
  if (args.size() < 3) throw InputError("usage: fix ID group-ID style args...");
  check_id(args[0], "fix");
  id = args[0];
  igroup = engine.groups->find_or_error(args[1], "fix " + args[0]);
  groupbit = engine.groups->bitmask(igroup);
  style = args[2];
}

long long Fix::clump_spheres_in_group() const {
  const Particles& p = *engine_.particles;
  long long mine = 0, all = 0;
  for (int i = 0; i < p.nlocal; ++i)
    if ((p.mask[i] & groupbit) && p.body[i] >= 0) ++mine;
  MPI_Allreduce(&mine, &all, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
  return all;
}

void Fix::require_free_spheres() const {
  const long long n = clump_spheres_in_group();
  if (n > 0) {
    throw InputError("fix " + id + " (" + style + "): " + std::to_string(n) +
                     " particles of its group are spheres of clumps, which fix multisphere moves; give it a "
                     "group of free spheres");
  }
}

}  // namespace granary
