#!/usr/bin/env bash
# Set up (packages, build) and run the demo: the small clogging silo of
# examples/silo_clogging on 2 MPI ranks (cylinders as 10-sphere clumps flow out
# through a slit until arches clog it; each arch is removed and the next
# avalanche starts), then its avalanche statistics and plots. Output goes to
# out/silo/ (extra arguments are passed to examples/silo_clogging/run.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/caller.sh
[ -n "${GRANARY_AS_CALLER:-}" ] || tools/setup.sh
rerun_as_caller "$@"
examples/silo_clogging/run.sh --out out/silo "$@"
echo "Demo output in out/silo: avalanches.csv and VTK series (particles_.pvd, bodies_.pvd, mesh_.pvd; open them in ParaView) in phi_0/, statistics and PNG plots in out/silo/"
