// Growth of the large arrays: per-particle fields, the neighbour list and the
// contact history aligned with it.
//
// std::vector doubles its capacity and copies into the new block while the
// old one is still allocated: for the arrays that set a run's peak memory that
// is three times the data for a moment and up to twice it for good. These
// helpers grow by a quarter instead, and, where the old contents are not
// needed, release the old block before taking the new one.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace granary {

/// Resize to n keeping the contents; a larger block is a quarter above the
/// old capacity (or n, when that is more).
template <class T>
void grow_keep(std::vector<T>& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(std::max(n, v.capacity() + v.capacity() / 4 + 16));
  v.resize(n);
}

/// n copies of `value`; the old contents are dropped, and with them the old
/// block before a larger one (an eighth above n) is taken.
template <class T>
void assign_fresh(std::vector<T>& v, std::size_t n, const T& value) {
  if (n > v.capacity()) {
    std::vector<T>().swap(v);
    v.reserve(n + n / 8);
  }
  v.assign(n, value);
}

}  // namespace granary
