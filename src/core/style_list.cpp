// The registered names of every kind (granary -list-styles).
#include "core/style_list.h"

#include <algorithm>

#include "contact/contact_model.h"
#include "core/registry.h"

namespace granary {

std::vector<std::pair<std::string, std::string>> registered_names() {
  std::vector<std::pair<std::string, std::string>> out;
  auto add = [&out](const std::string& kind, const std::vector<std::string>& names) {
    for (const auto& n : names)
      out.emplace_back(kind, n);
  };
  add("command", CommandRegistry::instance().names());
  add("fix", FixRegistry::instance().names());
  add("compute", ComputeRegistry::instance().names());
  add("pair", PairRegistry::instance().names());
  add("pair", {kPairNoneWord});
  add("region", RegionRegistry::instance().names());
  add("region", {kRegionDeleteWord});
  add("dump", DumpRegistry::instance().names());
  add("atom_style", atom_style_names());
  for (const auto& slot : contact::model_names())
    add(slot.first, slot.second);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace granary
