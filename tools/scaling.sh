#!/bin/bash
# Strong scaling of the large clump silo (examples/bench/README.md,
# "in.bench_silo_large"), the measurement of doc/performance.md "Strong
# scaling to 16 ranks", as one script for a machine with many cores:
#
#   tools/scaling.sh [--ranks 16,8,4,2,1] [--nsteps 1000] [--vf 0.3] [--settle 6000]
#                    [--balance 5] [--liggghts] [--contention] [--out DIR] [--granary BUILD]
#
# 1. inserts the bed on one rank (in.bench_silo_large -var nfill 1);
# 2. lets it settle with the shutter closed on the largest rank count
#    (in.bench_silo_large_run -var open 0 -var save 1);
# 3. discharges for nsteps on each rank count (tools/bench.py --only granary,
#    ranks bound to cores), then once more on the largest count with
#    `-var balance B` (0: none);
# 4. with --liggghts, the same for LIGGGHTS on the largest count and one rank
#    (its own insertion and settling; LIGGGHTS must be on PATH).
# 5. with --contention, the machine's own limit for this work: a bed of 1/N
#    the volume fraction (N the largest rank count) inserted and settled on
#    one rank, its one-rank discharge run alone and then as N copies at once,
#    each bound to its own core (taskset); the copies' slowdown is printed
#    (contention.txt): the efficiency no program reaches on N ranks there.
# With mpicc on PATH the discharges also record each rank's time inside
# blocking MPI calls (tools/bench.py --mpi-times: the transfers and the
# waits, per call, in a third table).
# Everything goes to DIR (default scaling_out): the restart files, the
# screen output of each step (NAME.screen: the bench.py tables are in
# *_discharge.screen and granary_balance.screen), bench.py's JSON and the
# programs' logs (bench.py --keep-output).
# Each step prints its wall time; the restart files are reused when present,
# so a second call (after a time limit) goes on where the first stopped.
# vf 0.03 gives a bed of about 20,000 particles for a quick try on a small
# machine.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
ranks=16,8,4,2,1
nsteps=1000
vf=0.3
settle=6000
balance=5
liggghts=0
contention=0
out=scaling_out
granary=$root/build/granary
while [ $# -gt 0 ]; do
  case $1 in
    --ranks) ranks=$2; shift 2 ;;
    --nsteps) nsteps=$2; shift 2 ;;
    --vf) vf=$2; shift 2 ;;
    --settle) settle=$2; shift 2 ;;
    --balance) balance=$2; shift 2 ;;
    --liggghts) liggghts=1; shift ;;
    --contention) contention=1; shift ;;
    --out) out=$2; shift 2 ;;
    --granary) granary=$(realpath "$2"); shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed -n 's/^# \{0,1\}//p'; exit 0 ;;
    *) echo "scaling.sh: unknown option '$1'; see tools/scaling.sh --help" >&2; exit 2 ;;
  esac
done
[ -x "$granary" ] || { echo "scaling.sh: no Granary executable at $granary (build it, or pass --granary)" >&2; exit 2; }
if [ "$liggghts" = 1 ] && ! command -v liggghts > /dev/null; then
  echo "scaling.sh: --liggghts, but no liggghts on PATH" >&2
  exit 2
fi
mkdir -p "$out"
out=$(realpath "$out")
bench=$root/examples/bench
nmax=$(echo "$ranks" | tr ',' '\n' | sort -n | tail -1)
mpi=(mpirun -np "$nmax" --bind-to core --map-by core)
[ "$(id -u)" = 0 ] && mpi+=(--allow-run-as-root)
[ "$nmax" -gt "$(nproc)" ] && mpi+=(--oversubscribe)
step() {  # step NAME COMMAND...: run it in $out (screen output to NAME.screen), print its wall time
  local name=$1 t0
  shift
  t0=$(date +%s%N)
  (cd "$out" && "$@") > "$out/$name.screen" 2>&1 || {
    echo "scaling.sh: $name failed; see $out/$name.screen" >&2
    exit 1
  }
  echo "$name: $(( ($(date +%s%N) - t0) / 1000000 )) ms"
}
mpitimes=()
[ "$nmax" -gt 1 ] && command -v mpicc > /dev/null && mpitimes=(--mpi-times)
echo "scaling.sh: $(nproc) cores, ranks $ranks, vf $vf, settle $settle, nsteps $nsteps; output in $out"
for prog in granary liggghts; do
  [ "$prog" = liggghts ] && [ "$liggghts" = 0 ] && continue
  exe=$granary
  [ "$prog" = liggghts ] && exe=liggghts
  p=${prog:0:1}
  if [ ! -e "$out/$p.settled.restart" ]; then
    [ -e "$out/$p.1.restart" ] ||
      step "${prog}_insert" "$exe" -in "$bench/in.bench_silo_large" -var dir "$bench" -var nfill 1 \
        -var vf "$vf" -var out "$out/$p.1.restart" -log "$out/$p.insert.log"
    step "${prog}_settle" "${mpi[@]}" "$exe" -in "$bench/in.bench_silo_large_run" -var dir "$bench" \
      -var in "$out/$p.1.restart" -var open 0 -var save 1 -var nsteps "$settle" -var out "$out/$p.settled.restart.tmp" \
      -log "$out/$p.settle.log"
    mv "$out/$p.settled.restart.tmp" "$out/$p.settled.restart"
  fi
  r=$ranks
  [ "$prog" = liggghts ] && r=$nmax,1
  step "${prog}_discharge" /usr/bin/python3 "$root/tools/bench.py" "$bench/in.bench_silo_large_run" --only "$prog" \
    --"$prog" "$exe" --ranks "$r" --nsteps "$nsteps" --var in "$out/$p.settled.restart" \
    --mpirun-args "--bind-to core --map-by core" --json "$out/$prog.json" --keep-output "$out/${prog}_logs" \
    "${mpitimes[@]}"
  if [ "$prog" = granary ] && [ "$balance" != 0 ]; then
    step granary_balance /usr/bin/python3 "$root/tools/bench.py" "$bench/in.bench_silo_large_run" \
      --only granary --granary "$exe" --ranks "$nmax" --nsteps "$nsteps" \
      --var in "$out/$p.settled.restart" --var balance "$balance" --mpirun-args "--bind-to core --map-by core" \
      --json "$out/granary_balance.json" --keep-output "$out/granary_balance_logs" "${mpitimes[@]}"
  fi
done
if [ "$contention" = 1 ]; then
  # the bed of one rank's share, settled on one rank
  vfc=$(awk -v v="$vf" -v n="$nmax" 'BEGIN { printf "%.6g", v / n }')
  if [ ! -e "$out/c.settled.restart" ]; then
    [ -e "$out/c.1.restart" ] ||
      step contention_insert "$granary" -in "$bench/in.bench_silo_large" -var dir "$bench" -var nfill 1 \
        -var vf "$vfc" -var out "$out/c.1.restart" -log "$out/c.insert.log"
    step contention_settle "$granary" -in "$bench/in.bench_silo_large_run" -var dir "$bench" \
      -var in "$out/c.1.restart" -var open 0 -var save 1 -var nsteps "$settle" -var out "$out/c.settled.restart.tmp" \
      -log "$out/c.settle.log"
    mv "$out/c.settled.restart.tmp" "$out/c.settled.restart"
  fi
  pin=()
  command -v taskset > /dev/null && pin=(taskset -c)
  copy() {  # copy NAME CORE: one one-rank discharge (bound to CORE with taskset)
    local where=()
    [ ${#pin[@]} -gt 0 ] && where=("${pin[@]}" "$2")
    (cd "$out" && "${where[@]}" "$granary" -in "$bench/in.bench_silo_large_run" -var dir "$bench" \
      -var in "$out/c.settled.restart" -var nsteps "$nsteps" -log "$out/$1.log" > "$out/$1.screen" 2>&1)
  }
  loop_s() { awk '/^Loop time of/ { print $4 }' "$out/$1.screen"; }
  copy c.alone 0 || { echo "scaling.sh: the lone copy failed; see $out/c.alone.screen" >&2; exit 1; }
  ncores=$(nproc)
  pids=()
  for ((k = 0; k < nmax; ++k)); do
    copy "c.copy$k" $((k % ncores)) &
    pids+=($!)
  done
  for k in "${!pids[@]}"; do
    wait "${pids[$k]}" || { echo "scaling.sh: copy $k failed; see $out/c.copy$k.screen" >&2; exit 1; }
  done
  alone=$(loop_s c.alone)
  loops=()
  for ((k = 0; k < nmax; ++k)); do
    loops+=("$(loop_s "c.copy$k")")
  done
  {
    echo "contention: $nmax copies of the one-rank discharge (vf $vfc, $nsteps steps) on $ncores cores" \
      "$([ ${#pin[@]} -gt 0 ] && echo "(each bound to a core)" || echo "(not bound: no taskset)")"
    echo "alone: loop $alone s"
    for k in "${!loops[@]}"; do
      echo "copy $k: loop ${loops[$k]} s"
    done
    printf '%s\n' "${loops[@]}" | awk -v alone="$alone" '{ s += $1; if ($1 > m) m = $1 } END {
      printf "copies: mean loop %.4g s, slowest %.4g s; alone / mean = %.3f (the efficiency the machine allows)\n",
        s / NR, m, alone / (s / NR) }'
  } > "$out/contention.txt"
fi
cat "$out"/*_discharge.screen "$out"/granary_balance.screen "$out"/contention.txt 2> /dev/null || true
