// Geometric regions (LAMMPS `region` command). A region answers whether a
// point is inside it; `side out` inverts the answer. Styles register with
// GRANARY_REGION_STYLE and parse their own arguments; common keywords
// (side in|out, units box|lattice) are handled by the base class.
#pragma once

#include <memory>
#include <string>

#include "core/utils.h"
#include "core/vec3.h"

namespace granary {

class Engine;

class Region {
 public:
  /// args = "ID style style-args... keywords..."; nshape = number of style args.
  Region(Engine& engine, const Args& args, std::size_t nshape);
  virtual ~Region() = default;

  /// True when x lies in the region (after `side`).
  bool match(const Vec3& x) const { return inside(x) == interior; }
  /// True when x lies inside the shape, ignoring `side`.
  virtual bool inside(const Vec3& x) const = 0;
  /// Axis-aligned bounds of the shape; false when unbounded (or side out).
  virtual bool bounds(Vec3& lo, Vec3& hi) const = 0;
  /// Volume of the shape where finite (for volume fractions), else -1.
  virtual double volume() const { return -1.0; }

  std::string id, style;
  bool interior = true;         // side in
  double scale[3] = {1, 1, 1};  // units lattice -> box factors

 protected:
  /// Parse a coordinate; "INF"/"EDGE" map to +-huge or the box edge.
  double coord(const std::string& word, int dim, bool lower) const;
  double length(const std::string& word, int dim) const;
  Engine& engine_;
};

}  // namespace granary
