#include "fix/fix.h"

#include "core/engine.h"
#include <cctype>

#include "core/error.h"
#include "domain/groups.h"

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

}  // namespace granary
