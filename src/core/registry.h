// One registry per kind of style, keyed by the name used in scripts.
//
// A style registers itself with one line next to its class, e.g.
//   GRANARY_FIX_STYLE("gravity", FixGravity)
// and core commands with
//   GRANARY_COMMAND("timestep", cmd_timestep)
// The library is linked as a whole archive so that every registration runs.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;
class Fix;
class Compute;
class Pair;
class Region;
class Dump;

template <class Factory>
class Registry {
 public:
  /// The registry of this kind (constructed on first use).
  static Registry& instance() {
    static Registry registry;
    return registry;
  }
  bool add(const std::string& name, Factory factory) {
    factories_[name] = std::move(factory);
    return true;
  }
  const Factory* find(const std::string& name) const {
    auto it = factories_.find(name);
    return it == factories_.end() ? nullptr : &it->second;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& kv : factories_)
      out.push_back(kv.first);
    return out;
  }

 private:
  std::map<std::string, Factory> factories_;
};

/// A script command: receives the words after the command name.
using CommandFn = std::function<void(Engine&, const Args&)>;
/// Fix and compute factories receive the full argument list "ID group style args...".
using FixFactory = std::function<std::unique_ptr<Fix>(Engine&, const Args&)>;
using ComputeFactory = std::function<std::unique_ptr<Compute>(Engine&, const Args&)>;
/// Pair styles receive the words after the style name.
using PairFactory = std::function<std::unique_ptr<Pair>(Engine&, const Args&)>;
/// Regions receive "ID style args...".
using RegionFactory = std::function<std::unique_ptr<Region>(Engine&, const Args&)>;
/// Dumps receive "ID group style N file args...".
using DumpFactory = std::function<std::unique_ptr<Dump>(Engine&, const Args&)>;

using CommandRegistry = Registry<CommandFn>;
using FixRegistry = Registry<FixFactory>;
using ComputeRegistry = Registry<ComputeFactory>;
using PairRegistry = Registry<PairFactory>;
using RegionRegistry = Registry<RegionFactory>;
using DumpRegistry = Registry<DumpFactory>;

}  // namespace granary

#define GRANARY_CONCAT_(a, b) a##b
#define GRANARY_CONCAT(a, b) GRANARY_CONCAT_(a, b)
#define GRANARY_UNIQUE(prefix) GRANARY_CONCAT(prefix, __LINE__)

#define GRANARY_COMMAND(name, fn)                                 \
  static const bool GRANARY_UNIQUE(granary_command_registered_) = \
      ::granary::CommandRegistry::instance().add(name, fn)

#define GRANARY_FIX_STYLE(name, Class)                                                                \
  static const bool GRANARY_UNIQUE(granary_fix_registered_) = ::granary::FixRegistry::instance().add( \
      name, [](::granary::Engine& e, const ::granary::Args& a) -> std::unique_ptr<::granary::Fix> {   \
        return std::make_unique<Class>(e, a);                                                         \
      })

#define GRANARY_COMPUTE_STYLE(name, Class)                                                                  \
  static const bool GRANARY_UNIQUE(granary_compute_registered_) =                                           \
      ::granary::ComputeRegistry::instance().add(                                                           \
          name, [](::granary::Engine& e, const ::granary::Args& a) -> std::unique_ptr<::granary::Compute> { \
            return std::make_unique<Class>(e, a);                                                           \
          })

#define GRANARY_PAIR_STYLE(name, Class)                                                                 \
  static const bool GRANARY_UNIQUE(granary_pair_registered_) = ::granary::PairRegistry::instance().add( \
      name, [](::granary::Engine& e, const ::granary::Args& a) -> std::unique_ptr<::granary::Pair> {    \
        return std::make_unique<Class>(e, a);                                                           \
      })

#define GRANARY_REGION_STYLE(name, Class)                                                                   \
  static const bool GRANARY_UNIQUE(granary_region_registered_) = ::granary::RegionRegistry::instance().add( \
      name, [](::granary::Engine& e, const ::granary::Args& a) -> std::unique_ptr<::granary::Region> {      \
        return std::make_unique<Class>(e, a);                                                               \
      })

#define GRANARY_DUMP_STYLE(name, Class)                                                                 \
  static const bool GRANARY_UNIQUE(granary_dump_registered_) = ::granary::DumpRegistry::instance().add( \
      name, [](::granary::Engine& e, const ::granary::Args& a) -> std::unique_ptr<::granary::Dump> {    \
        return std::make_unique<Class>(e, a);                                                           \
      })
