// Helpers shared by the region styles.
#pragma once

#include <string>

#include "core/error.h"
#include "core/vec3.h"

namespace granary {
namespace region_util {

/// Magnitude used for INF bounds (as in LAMMPS); bounds at or beyond it are unbounded.
constexpr double kBig = 1.0e20;

inline bool is_infinite(double v) {
  return v <= -kBig || v >= kBig;
}

/// Axis letter x, y or z as 0, 1, 2.
inline int parse_axis(const std::string& word, const std::string& what) {
  if (word == "x") return 0;
  if (word == "y") return 1;
  if (word == "z") return 2;
  throw InputError(what + " must be x, y or z, got '" + word + "'");
}

/// Bounds of a solid of revolution about the axis `axis` (the other two
/// dimensions a and b, centre c1, c2), at most `radius` from the axis and
/// between lo and hi along it.
inline void axial_bounds(int axis, int a, int b, double c1, double c2, double radius, double lo_axis,
                         double hi_axis, Vec3& lo, Vec3& hi) {
  lo[a] = c1 - radius;
  hi[a] = c1 + radius;
  lo[b] = c2 - radius;
  hi[b] = c2 + radius;
  lo[axis] = lo_axis;
  hi[axis] = hi_axis;
}

}  // namespace region_util
}  // namespace granary
