// Results of the same IEEE operations in the same order are identical to the
// last bit (and in sign; two NaNs count as the same). A build that lets the
// compiler fuse multiplies and adds (-mfma, -march=native) may fuse two code
// paths differently; there they agree to round-off.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec3.h"

namespace granary::test {

inline bool same_bits(double a, double b) {
#if defined(__FMA__)
  return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)) + 1e-300;
#else
  return (a == b && std::signbit(a) == std::signbit(b)) || (std::isnan(a) && std::isnan(b));
#endif
}

inline bool same_bits(const Vec3& a, const Vec3& b) {
  return same_bits(a[0], b[0]) && same_bits(a[1], b[1]) && same_bits(a[2], b[2]);
}

}  // namespace granary::test
