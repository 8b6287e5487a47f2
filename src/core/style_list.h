// The names a script can use, by kind: what `granary -list-styles` prints
// (doc/command_line.md) and tools/liggghts_coverage.py compares with the
// LIGGGHTS manual.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace granary {

/// The styles the atom_style command accepts.
const std::vector<std::string>& atom_style_names();

/// `region ID delete` removes a region; the word takes the place of a style.
inline constexpr const char* kRegionDeleteWord = "delete";
/// `pair_style none` removes the pair style (no pair forces).
inline constexpr const char* kPairNoneWord = "none";

/// Every name, as (kind, name) pairs sorted by kind and name. Kinds:
/// "command", "fix", "compute", "pair", "region", "dump" (the registries of
/// core/registry.h; "pair" also lists none, "region" the delete word), "atom_style", and
/// the contact sub-model slots of pair_style gran and fix wall/gran: "model",
/// "tangential", "rolling_friction", "cohesion", "surface", "damping".
std::vector<std::pair<std::string, std::string>> registered_names();

}  // namespace granary
