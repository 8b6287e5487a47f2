#!/usr/bin/env bash
# Set up (packages, build) and run the whole test suite. This is the README's
# test command, and what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/caller.sh
[ -n "${GRANARY_AS_CALLER:-}" ] || tools/setup.sh
rerun_as_caller "$@"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# The fuzz targets (clang, libFuzzer; doc/fuzzing.md) for 30 s each; then the
# suite, whose ctest summary is the last thing printed.
tools/fuzz.sh 30
cd build
ctest --output-on-failure --timeout 900 -j "$(nproc 2>/dev/null || echo 2)"
