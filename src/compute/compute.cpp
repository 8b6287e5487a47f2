#include "compute/compute.h"

#include "core/engine.h"
#include <cctype>

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

}  // namespace granary
