// Helpers shared by the region styles.
#pragma once

#include <string>

#include "core/error.h"

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

}  // namespace region_util
}  // namespace granary
