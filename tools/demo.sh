#!/usr/bin/env bash
# Set up (packages, build) and run the demo: a small, fast version of the silo
# clogging study (examples/silo_study) on 2 MPI ranks. Cylinders (clumps of 10
# spheres) mixed with 2 mm glass spheres (10 % of the solid volume) discharge
# through a slit in an 8 x 4 dc silo; every clog's arch (the lowest layer of
# bodies over the slit) is removed and the next avalanche starts; the silo is
# refilled from its restart file whenever the bed over the slit falls below
# the stop height; until 20 non-empty avalanches. Then the statistics and
# their plots, and a ParaView picture of a clog. Output in out/demo/ (a second
# run starts over). About 3 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/caller.sh
[ -n "${GRANARY_AS_CALLER:-}" ] || tools/setup.sh
rerun_as_caller "$@"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
PY=/usr/bin/python3
OUT=out/demo
CASE=r1.6_phi0.1
rm -rf "$OUT"
start=$SECONDS
# the geometry of the demo (the study's is 12 x 6 dc, fill 17 dc, stop 11.5 dc, a 6 x 6 x 5 dc box)
GEOMETRY=(-var W 8 -var D 4 -var H 16 -var s 2.0 -var fill 12 -var stop 8 -var column_w 3
          -var box_w 4 -var box_h 3 -var box_z 2.5 -var settle 0.15 -var box_every 500)
"$PY" tools/silo_study.py run --case "$CASE" --np 2 --data "$OUT/results" --work "$OUT/work" \
  --min-avalanches 20 --max-cycles 12 "${GEOMETRY[@]}"
"$PY" tools/silo_study_analysis.py --data "$OUT/results" --out "$OUT" --bootstrap 1000 > "$OUT/summary.txt"
"$PY" tools/silo_study.py picture --case "$CASE" --data "$OUT/results" --work "$OUT/work" --out "$OUT/clog.png"
"$PY" tools/silo_study.py status --data "$OUT/results"
"$PY" - "$OUT/summary.json" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
for name, c in s["cases"].items():
    print(f"{name}: {c['n']} non-empty avalanches ({c['n_empty']} empty) in {c['cycles']} cycles; "
          f"<S> = {1e3 * c['S_mean']:.3g} g (95 % CI {1e3 * c['S_ci95_boot'][0]:.3g} - {1e3 * c['S_ci95_boot'][1]:.3g}), "
          f"{c['bodies_mean']:.0f} bodies; sd/<S> = {c['cv']:.2f} (exponential: 1), KS p = {c['ks_p']:.2f}; "
          f"{c['arch_removed_mean']:.1f} bodies removed per arch")
    if "box_phi" in c:
        print(f"  box over the slit while flowing: solid fraction {c['box_phi']:.3f}, "
              f"cylinders at {c['box_theta']:.1f} degrees to the vertical")
EOF
echo "Demo output in $OUT ($((SECONDS - start)) s): distributions.png (P(S/<S>) with exp(-x)), box.png,"
echo "summary.md and summary.json (the statistics), clog.png (ParaView picture of a clog), results/$CASE/"
echo "(avalanches.csv, box.csv, cycles.csv); the clog's VTK files are in $OUT/work/$CASE/picture/ for ParaView"
