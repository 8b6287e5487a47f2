#include "core/force.h"

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/style_list.h"
#include "neighbor/contact_history.h"
#include "pair/pair.h"

namespace granary {

Force::Force(Engine& engine) : engine_(engine) {}
Force::~Force() = default;

ContactHistory* Force::contact_history() const {
  if (pending_history) return pending_history.get();
  return pair ? pair->history() : nullptr;
}

void Force::create_pair(const Args& args) {
  if (args.empty()) throw InputError("usage: pair_style STYLE args...");
  if (args[0] == kPairNoneWord) {
    pair.reset();
    pair_style = kPairNoneWord;
    return;
  }
  const auto& registry = PairRegistry::instance();
  const PairFactory* factory = registry.find(args[0]);
  if (!factory) {
    const std::string hint = did_you_mean(args[0], registry.names());
    throw InputError("unknown pair style '" + args[0] + "'" +
                     (hint.empty() ? "; see doc/pairs for the list" : "; " + hint));
  }
  pair = (*factory)(engine_, Args(args.begin() + 1, args.end()));
  pair_style = args[0];
  pair_words.assign(args.begin() + 1, args.end());
}

}  // namespace granary
