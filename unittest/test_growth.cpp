// The growth of the large arrays (src/core/growth.h): contents kept or
// replaced as stated, capacity at most a quarter (grow_keep) or an eighth
// (assign_fresh) above what is asked, where std::vector would double.
#include <catch2/catch.hpp>

#include <cstddef>
#include <vector>

#include "core/growth.h"

using granary::assign_fresh;
using granary::grow_keep;

TEST_CASE("grow_keep keeps the contents and grows by a quarter", "[growth]") {
  std::vector<double> v;
  std::size_t reallocations = 0;
  for (std::size_t n = 1; n <= 100000; ++n) {
    const std::size_t before = v.capacity();
    grow_keep(v, n);
    v[n - 1] = static_cast<double>(n);
    reallocations += v.capacity() != before;
    REQUIRE(v.size() == n);
    REQUIRE(v.capacity() <= n + n / 4 + 16);
  }
  for (std::size_t k = 0; k < v.size(); ++k)
    REQUIRE(v[k] == static_cast<double>(k + 1));
  // geometric growth: a few dozen blocks for 100,000 single appends
  CHECK(reallocations < 60);
  grow_keep(v, 10);  // shrinking keeps the block
  CHECK(v.size() == 10);
  CHECK(v[9] == 10.0);
}

TEST_CASE("assign_fresh fills, and takes a block an eighth above the size", "[growth]") {
  std::vector<int> v(100, 7);
  assign_fresh(v, 50, 3);  // fits: same block
  CHECK(v.size() == 50);
  CHECK(v.capacity() == 100);
  CHECK(v[49] == 3);
  assign_fresh(v, 8000, -1);
  CHECK(v.size() == 8000);
  CHECK(v.capacity() == 9000);
  CHECK(v.front() == -1);
  CHECK(v.back() == -1);
}
