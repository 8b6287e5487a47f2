// Named particle groups as bits of the per-particle mask (at most 32, "all" is bit 0).
#pragma once

#include <array>
#include <string>

#include "core/utils.h"
#include "core/vec3.h"

namespace granary {

class Engine;
class Region;

class Groups {
 public:
  static constexpr int kMaxGroups = 32;
  explicit Groups(Engine& engine);

  /// Index of a group, or -1.
  int find(const std::string& name) const;
  /// Index of a group or InputError naming `what` with a suggestion.
  int find_or_error(const std::string& name, const std::string& what) const;
  int bitmask(int index) const { return 1 << index; }
  /// Create the group if needed and return its index.
  int find_or_create(const std::string& name);
  /// The `group` command.
  void command(const Args& args);

  // group functions (collective over ranks); region may be null
  double count(int igroup, const Region* region = nullptr) const;
  double mass(int igroup, const Region* region = nullptr) const;
  Vec3 xcm(int igroup, const Region* region = nullptr) const;
  Vec3 vcm(int igroup, const Region* region = nullptr) const;
  void bounds(int igroup, Vec3& lo, Vec3& hi, const Region* region = nullptr) const;
  /// Angular velocity w = I^-1 L of the rigid rotation that carries the
  /// group's orbital angular momentum L about xcm (I, L of point masses at the
  /// unwrapped positions; directions without inertia, e.g. along a line of
  /// particles, get none).
  Vec3 omega(int igroup, const Vec3& xcm) const;

  /// Position of owned particle i unwrapped across periodic boundaries.
  Vec3 unwrapped(int i) const;

  std::array<std::string, kMaxGroups> names;

 private:
  Engine& engine_;
};

}  // namespace granary
