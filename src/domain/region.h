// Geometric regions (LAMMPS `region` command). A region answers whether a
// point is inside it; `side out` inverts the answer. Styles register with
// GRANARY_REGION_STYLE and parse their own arguments; common keywords
// (side in|out, units box|lattice) are handled by the base class.
#pragma once

#include <memory>
#include <string>
#include <vector>

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
  /// True when this region is made of region `other` (union, intersect).
  virtual bool uses(const std::string& other) const { return false; }

  /// A point of the region's surface seen from a point x in the region: the
  /// distance r from x to it and the vector del = x - point (|del| = r).
  struct SurfacePoint {
    double r;
    Vec3 del;
  };
  /// The surface points within `cutoff` of x (cleared first), x being in the
  /// region (match(x)): with side in, the nearest point of every face of the
  /// shape closer than cutoff (a block's corner has three, a cylinder's rim
  /// two); with side out, the nearest point of the shape. Nothing for an x
  /// outside the region, nor for the points equally near in every direction
  /// (the centre of a sphere, the axis of a cylinder). InputError for a style
  /// without this geometry.
  void surface(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const {
    out.clear();
    if (!match(x)) return;
    if (interior)
      surface_interior(x, cutoff, out);
    else
      surface_exterior(x, cutoff, out);
  }

  std::string id, style;
  bool interior = true;         // side in
  double scale[3] = {1, 1, 1};  // units lattice -> box factors

 protected:
  /// Parse a coordinate; "INF"/"EDGE" map to +-huge or the box edge.
  double coord(const std::string& word, int dim, bool lower) const;
  double length(const std::string& word, int dim) const;
  /// surface() for side in (x inside the shape) and side out (x outside it).
  virtual void surface_interior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const;
  virtual void surface_exterior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const;
  Engine& engine_;
};

}  // namespace granary
