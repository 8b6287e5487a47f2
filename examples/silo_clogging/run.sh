#!/usr/bin/env bash
# Run the silo clogging example and analyse it:
#   1. write the silo meshes (tools/make_silo_stl.py),
#   2. run in.silo with mpirun on NP ranks, once per sphere fraction phi,
#   3. avalanche statistics (tools/avalanche_stats.py) and the box averages
#      (tools/silo_box_analysis.py) over the cases, with plots;
#   4. after each case, a ParaView picture of its final state, DIR/clog_phi_<phi>.png
#      (tools/render.py), when pvbatch can import paraview.simple.
#
# Usage: examples/silo_clogging/run.sh [--out DIR] [--np N] [--phi "0 0.05 ..."] [-var NAME VALUE ...]
#   --out DIR   output folder (default out/silo, relative to the repository root)
#   --np N      MPI ranks (default 2)
#   --phi LIST  sphere volume fractions, one run each (default "0")
#   -var ...    passed on to granary (e.g. -var W 30 -var D 10 -var H 70 ...);
#               W, D, H and s also shape the meshes
# Each case goes to DIR/phi_<phi>/ (log.silo, avalanches.csv, box.dat, VTK
# files); the analysis and the pictures to DIR/ (avalanche_stats.csv,
# box_stats.csv, *.png, clog_phi_<phi>.png).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
OUT="$ROOT/out/silo"
NP=2
PHIS="0"
VARS=()
declare -A GEOM=([W]=10 [D]=3 [H]=22 [s]=2.2)
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) OUT="$2"; shift 2 ;;
    --np) NP="$2"; shift 2 ;;
    --phi) PHIS="$2"; shift 2 ;;
    -var)
      [[ $# -ge 3 ]] || { echo "run.sh: -var needs a name and a value" >&2; exit 2; }
      if [[ -n "${GEOM[$2]+x}" ]]; then GEOM[$2]="$3"; fi
      if [[ "$2" == phi ]]; then echo "run.sh: give phi with --phi" >&2; exit 2; fi
      VARS+=(-var "$2" "$3"); shift 3 ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "run.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

GRANARY="$ROOT/build/granary"
if [[ ! -x "$GRANARY" ]]; then
  echo "building granary in $ROOT/build ..."
  cmake -S "$ROOT" -B "$ROOT/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$ROOT/build" -j2 --target granary
fi
PY=/usr/bin/python3
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

# ParaView pictures (tools/render.py): pvbatch with the paraview Python module; Debian's
# ParaView renders through X only, so without a display under xvfb-run (-noreset: the
# server must survive pvbatch closing its first connection)
RENDER=() RENDER_SKIP=""
if ! command -v pvbatch >/dev/null 2>&1; then
  RENDER_SKIP="no pvbatch (Debian packages paraview, python3-paraview)"
else
  probe="$(mktemp --suffix .py)"
  echo "import paraview.simple" > "$probe"
  if ! pvbatch "$probe" >/dev/null 2>&1; then
    RENDER_SKIP="pvbatch cannot import paraview.simple (Debian package python3-paraview)"
  elif [[ -z "${DISPLAY:-}" ]] && command -v xvfb-run >/dev/null 2>&1; then
    RENDER=(xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" pvbatch)
  else
    RENDER=(pvbatch)
  fi
  rm -f "$probe"
fi

"$PY" "$ROOT/tools/make_silo_stl.py" --W "${GEOM[W]}" --D "${GEOM[D]}" --H "${GEOM[H]}" --slit "${GEOM[s]}" \
  --out "$OUT"

CSVS=() BOXES=() PHILIST=()
for phi in $PHIS; do
  dir="$OUT/phi_$phi"
  mkdir -p "$dir"
  echo "=== phi = $phi: $dir"
  start=$(date +%s)
  (cd "$dir" && mpirun -np "$NP" "$GRANARY" -in "$ROOT/examples/silo_clogging/in.silo" -log log.silo \
     -var phi "$phi" -var meshdir "$OUT" -var potdir "$ROOT/potentials" -var out . "${VARS[@]}" \
     > screen.txt)
  echo "    $(grep '^SILO' "$dir/log.silo" || true)"
  echo "    wall time $(( $(date +%s) - start )) s"
  png="$OUT/clog_phi_$phi.png"
  if [[ -n "$RENDER_SKIP" ]]; then
    echo "    picture skipped: $RENDER_SKIP"
  elif "${RENDER[@]}" "$ROOT/tools/render.py" "$dir" --out "$png" > "$dir/render.log" 2>&1; then
    echo "    picture $png"
  else
    echo "    picture not written: tools/render.py failed ($(grep -m1 'error' "$dir/render.log" || tail -n1 "$dir/render.log"))"
  fi
  CSVS+=("$dir/avalanches.csv") BOXES+=("$dir/box.dat") PHILIST+=("$phi")
done

"$PY" "$ROOT/tools/avalanche_stats.py" "${CSVS[@]}" --phi "${PHILIST[@]}" --out "$OUT"
"$PY" "$ROOT/tools/silo_box_analysis.py" --box "${BOXES[@]}" --avalanches "${CSVS[@]}" --phi "${PHILIST[@]}" \
  --out "$OUT"
echo "Output in $OUT: avalanche_stats.csv, avalanche_ccdf.png, avalanche_mean.png, box_stats.csv,"
echo "box_vs_phi.png, box_timeseries.png, clog_phi_*.png (final state, when ParaView could render);"
echo "per case phi_*/: log.silo, avalanches.csv, box.dat and VTK files"
echo "(open phi_*/particles_.pvd, bodies_.pvd and mesh_.pvd in ParaView; the final state: clog_*.vtp)"
