#!/usr/bin/env bash
# Build the libFuzzer target of the input language with clang (in build-fuzz/)
# and run it from the seed corpus for a bounded time. Any crash, sanitizer
# report or hang fails the run.
# Usage: tools/fuzz.sh [SECONDS]   (default 60)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
if ! command -v clang++ > /dev/null; then
  echo "fuzz: clang++ is not installed (apt-get install clang libclang-rt-14-dev)" >&2
  exit 1
fi
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Release \
  -DGRANARY_TESTS=OFF -DGRANARY_FUZZ=ON > build-fuzz.log 2>&1 || { cat build-fuzz.log; exit 1; }
cmake --build build-fuzz --target fuzz_input -j "$(nproc 2>/dev/null || echo 2)" >> build-fuzz.log 2>&1 ||
  { tail -40 build-fuzz.log; exit 1; }
mkdir -p build-fuzz/corpus_work
echo "fuzz: running the input-language fuzzer for ${seconds} s"
build-fuzz/unittest/fuzz/fuzz_input -max_total_time="$seconds" -max_len=4096 -timeout=10 \
  -print_final_stats=1 build-fuzz/corpus_work unittest/fuzz/corpus 2>&1 | tail -15
echo "fuzz: no crash in ${seconds} s"
