// A build for AVX2 (CMake option GRANARY_SIMD, doc/clusters.md) stops with a
// message on a processor without AVX2 instead of dying on the first packed
// instruction. The check runs before the static initialisers of the rest of
// the program (constructor priority 101) and this file is compiled without
// AVX (CMakeLists.txt), so nothing before it can use AVX2.
#include <cstdio>
#include <cstdlib>

namespace {

#if defined(__AVX__)
#error "src/core/cpu_check.cpp must be compiled without AVX (see CMakeLists.txt)"
#endif

[[gnu::constructor(101)]] void granary_cpu_check() {
#if defined(GRANARY_BUILT_FOR_AVX2) && (defined(__x86_64__) || defined(__i386__))
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2")) {
    std::fprintf(stderr,
                 "ERROR: this Granary was built for processors with AVX2 (CMake option GRANARY_SIMD), "
                 "and this processor has no AVX2. Build it on this kind of machine, or for any x86-64 "
                 "processor with: cmake -S . -B build -DGRANARY_SIMD=BASELINE (doc/clusters.md)\n");
    std::exit(1);
  }
#endif
}

}  // namespace
