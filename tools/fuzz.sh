#!/usr/bin/env bash
# Build the libFuzzer targets with clang (in build-fuzz/) and run each from its
# seed corpus for a bounded time. Any crash, sanitizer report or hang fails the
# run; the input that caused it is kept in build-fuzz/artifacts/.
# Usage: tools/fuzz.sh [SECONDS [TARGET...]]
#   SECONDS  per target (default 60)
#   TARGET   input (the input language), restart, stl, clump (the file readers
#            behind a few steps of a simulation), run (small random scripts);
#            default: all five
# See doc/fuzzing.md.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(input restart stl clump run)
if ! command -v clang++ > /dev/null; then
  echo "fuzz: clang++ is not installed (apt-get install clang libclang-rt-14-dev)" >&2
  exit 1
fi
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Release \
  -DGRANARY_TESTS=OFF -DGRANARY_FUZZ=ON > build-fuzz.log 2>&1 || { cat build-fuzz.log; exit 1; }
names=()
for t in "${targets[@]}"; do
  case $t in
    input | restart | stl | clump | run) names+=("fuzz_$t") ;;
    *) echo "fuzz: unknown target '$t' (input, restart, stl, clump, run)" >&2; exit 2 ;;
  esac
done
echo "fuzz: building ${names[*]} (build-fuzz.log)"
cmake --build build-fuzz --target "${names[@]}" -j "$(nproc 2>/dev/null || echo 2)" >> build-fuzz.log 2>&1 ||
  { tail -40 build-fuzz.log; exit 1; }
mkdir -p build-fuzz/artifacts
# What Open MPI keeps until the process ends is not a leak of Granary's: no
# leak check at exit (some of it is in plugins unloaded by then, which no
# suppression can name); libFuzzer still checks every input for leaks.
export LSAN_OPTIONS="suppressions=$root/unittest/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export ASAN_OPTIONS="leak_check_at_exit=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
for t in "${targets[@]}"; do
  if [ "$t" = input ]; then
    seeds=$root/unittest/fuzz/corpus max_len=4096
  else
    seeds=$root/unittest/fuzz/corpus_$t max_len=65536
  fi
  work=$root/build-fuzz/corpus_${t}_work
  mkdir -p "$work"
  echo "fuzz: running fuzz_$t for ${seconds} s"
  status=0
  build-fuzz/unittest/fuzz/fuzz_"$t" -max_total_time="$seconds" -max_len="$max_len" -timeout=20 \
    -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix="$root/build-fuzz/artifacts/${t}-" \
    "$work" "$seeds" > "build-fuzz/fuzz_$t.log" 2>&1 || status=$?
  if [ $status -ne 0 ]; then
    tail -60 "build-fuzz/fuzz_$t.log"
    echo "fuzz: fuzz_$t FAILED (exit $status); the input is in build-fuzz/artifacts/" >&2
    exit 1
  fi
  grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb" "build-fuzz/fuzz_$t.log" | sed 's/^/  /'
  echo "fuzz: fuzz_$t: no crash in ${seconds} s"
done
