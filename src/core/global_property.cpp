#include "core/global_property.h"

#include "core/error.h"

namespace granary {

double GlobalProperty::per_type(int t) const {
  if (t < 1 || t > static_cast<int>(values.size())) {
    throw InputError("property " + name + " has " + std::to_string(values.size()) +
                     " per-type value(s); type " + std::to_string(t) + " has none");
  }
  return values[t - 1];
}

double GlobalProperty::per_pair(int a, int b) const {
  const int nrows = static_cast<int>(values.size()) / ncols;
  if (a < 1 || a > nrows || b < 1 || b > ncols) {
    throw InputError("property " + name + " is a " + std::to_string(nrows) + " x " + std::to_string(ncols) +
                     " table; types (" + std::to_string(a) + ", " + std::to_string(b) + ") are outside it");
  }
  return values[static_cast<std::size_t>(a - 1) * ncols + (b - 1)];
}

}  // namespace granary
