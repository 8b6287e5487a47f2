#include "compute/compute.h"

#include <cctype>
#include <cstdio>

#include "comm/comm.h"
#include "core/engine.h"
#include "domain/domain.h"
#include "neighbor/neighbor.h"

#include "core/error.h"
#include "domain/groups.h"

namespace granary {

Compute::Compute(Engine& engine, const Args& args) : engine_(engine), args_(args) {
  if (args.size() < 3) throw InputError("usage: compute ID group-ID style args...");
  for (char c : args[0]) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) {
      throw InputError("compute ID '" + args[0] + "' may use only letters, digits and underscores");
    }
  }
  id = args[0];
  igroup = engine.groups->find_or_error(args[1], "compute " + args[0]);
  groupbit = engine.groups->bitmask(igroup);
  style = args[2];
}

void Compute::require_ghost_reach(double cutoff) const {
  const double reach = engine_.comm->cutghost - engine_.neighbor->skin;
  const auto& per = engine_.domain->periodic;
  if ((engine_.nprocs > 1 || per[0] || per[1] || per[2]) && cutoff > reach) {
    char msg[200];
    std::snprintf(msg, sizeof msg, "cutoff %g is longer than the ghost shell allows (%g)", cutoff, reach);
    throw InputError("compute " + id + " " + style + ": " + msg +
                     "; widen the shell with comm_modify cutoff (cutoff + skin)");
  }
}

}  // namespace granary
