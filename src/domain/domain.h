// The simulation box, its boundaries, this rank's subdomain and the regions.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace granary {

class Engine;
class Region;

class Domain {
 public:
  explicit Domain(Engine& engine);
  ~Domain();

  bool box_exist = false;
  std::string units = "si";
  int dimension = 3;

  /// Boundary letter per dimension and side: 'p' periodic, 'f' fixed,
  /// 's' shrink-wrapped, 'm' shrink-wrapped with the initial box as minimum.
  std::array<std::array<char, 2>, 3> boundary{{{'p', 'p'}, {'p', 'p'}, {'p', 'p'}}};
  std::array<bool, 3> periodic{{true, true, true}};

  Vec3 boxlo{0, 0, 0}, boxhi{0, 0, 0}, prd{0, 0, 0};
  Vec3 minlo{0, 0, 0}, minhi{0, 0, 0};  // box as created (minimum for 'm')
  Vec3 sublo{0, 0, 0}, subhi{0, 0, 0};  // this rank's subdomain

  // lattice (for `units lattice` and create_atoms on a lattice)
  std::string lattice_style = "none";
  double lattice_spacing[3] = {1, 1, 1};
  std::vector<Vec3> lattice_basis;  // fractional basis positions

  void set_box(const Vec3& lo, const Vec3& hi);
  /// Recompute shrink-wrapped bounds from the particles (collective).
  void reset_box();
  /// Wrap a position back into a periodic box, updating image flags.
  void remap(Vec3& x, int& image) const;
  bool inside_box(const Vec3& x) const;
  double volume() const { return prd.x() * prd.y() * prd.z(); }

  void add_region(const std::vector<std::string>& args);
  void delete_region(const std::string& id);
  Region* find_region(const std::string& id) const;
  /// find_region or InputError naming `what` with a suggestion.
  Region* region_or_error(const std::string& id, const std::string& what) const;

  std::vector<std::unique_ptr<Region>> regions;

 private:
  Engine& engine_;
};

}  // namespace granary
