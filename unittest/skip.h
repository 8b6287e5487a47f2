// Skipping a test whose reference is missing (LIGGGHTS or one of its
// tutorials not installed). Catch2 v2 has no skip of its own: skip() prints a
// line that ctest recognises (SKIP_REGULAR_EXPRESSION in CMakeLists.txt), so
// ctest reports the test as skipped, never as passed. The caller returns.
#pragma once

#include <iostream>
#include <string>

namespace granary::test {

inline void skip(const std::string& reason) {
  std::cout << "GRANARY_TEST_SKIPPED: " << reason << std::endl;
}

}  // namespace granary::test
