#!/bin/bash
# Strong scaling of the large clump silo (examples/bench/README.md,
# "in.bench_silo_large"), the measurement of doc/performance.md "Strong
# scaling to 16 ranks", as one script for a machine with many cores:
#
#   tools/scaling.sh [--ranks 16,8,4,2,1] [--nsteps 1000] [--vf 0.3] [--settle 6000]
#                    [--balance 5] [--liggghts] [--contention] [--contention-steps 2000]
#                    [--out DIR] [--granary BUILD]
#
# 1. inserts the bed on one rank (in.bench_silo_large -var nfill 1);
# 2. lets it settle with the shutter closed on the largest rank count
#    (in.bench_silo_large_run -var open 0 -var save 1);
# 3. discharges for nsteps on each rank count (tools/bench.py --only granary,
#    ranks bound to cores), then once more on the largest count with
#    `-var balance B` (0: none);
# 4. with --liggghts, the same for LIGGGHTS on the largest count and one rank
#    (its own insertion and settling; LIGGGHTS must be on PATH).
# 5. with --contention, the machine's own limit for this work: the settled
#    bed cut into the N boxes of the N-rank processor grid (N the largest
#    rank count; in.bench_silo_large_run -var part K), each box's particles
#    discharged on one rank for --contention-steps steps, first each alone,
#    then all N at once, each bound to its own core (taskset). The shares'
#    summed loop times alone over beside the others (contention.txt) is the
#    efficiency no program reaches on N ranks there: the same work without
#    communication, slowed only by what the cores share (memory, caches,
#    clock). The time all ran together is printed too.
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
csteps=2000
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
    --contention-steps) csteps=$2; shift 2 ;;
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
  # the shares of the largest rank count: its processor grid (read_restart
  # prints it) cut into equal boxes, each box's particles alone on one rank
  grid=$(cd "$out" && "${mpi[@]}" "$granary" -in "$bench/in.bench_silo_large_run" -var dir "$bench" \
    -var in "$out/g.settled.restart" -var nsteps 0 -log none 2>&1 | awk '/MPI processor grid/ { print $1, $3, $5; exit }')
  read -r px py pz <<< "$grid"
  if [ -z "$pz" ] || [ "$pz" != 1 ] || [ $((px * py)) != "$nmax" ]; then
    echo "scaling.sh: --contention expects a grid of $nmax x 1 boxes in z on $nmax ranks, found '$grid'" >&2
    exit 1
  fi
  pin=()
  command -v taskset > /dev/null && pin=(taskset -c)
  share() {  # share NAME K CORE: box K's one-rank discharge (bound to CORE with taskset); NAME.span: start and end (s)
    local where=() t0 rc=0
    [ ${#pin[@]} -gt 0 ] && where=("${pin[@]}" "$3")
    t0=$(date +%s.%N)
    (cd "$out" && "${where[@]}" "$granary" -in "$bench/in.bench_silo_large_run" -var dir "$bench" \
      -var in "$out/g.settled.restart" -var part "$2" -var px "$px" -var py "$py" -var nsteps "$csteps" \
      -log "$out/$1.log" > "$out/$1.screen" 2>&1) || rc=$?
    echo "$t0 $(date +%s.%N)" > "$out/$1.span"
    return $rc
  }
  # (the last run: a share's run of no steps that sorts it comes first)
  loop_s() { awk '/^Loop time of/ { t = $4 } END { print t }' "$out/$1.screen"; }
  atoms() { awk '/^Loop time of/ { n = $(NF - 1) } END { print n }' "$out/$1.screen"; }
  t0=$(date +%s%N)
  for ((k = 0; k < nmax; ++k)); do
    share "c.alone$k" "$k" 0 || { echo "scaling.sh: share $k alone failed; see $out/c.alone$k.screen" >&2; exit 1; }
  done
  ncores=$(nproc)
  pids=()
  for ((k = 0; k < nmax; ++k)); do
    share "c.copy$k" "$k" $((k % ncores)) &
    pids+=($!)
  done
  for k in "${!pids[@]}"; do
    wait "${pids[$k]}" || { echo "scaling.sh: share $k beside the others failed; see $out/c.copy$k.screen" >&2; exit 1; }
  done
  echo "contention: $(( ($(date +%s%N) - t0) / 1000000 )) ms"
  {
    echo "contention: the bed cut into the $nmax boxes of the $px x $py grid of $nmax ranks, each box's" \
      "particles discharged for $csteps steps on one rank, alone and all $nmax at once on $ncores cores" \
      "$([ ${#pin[@]} -gt 0 ] && echo "(each bound to a core)" || echo "(not bound: no taskset)")"
    for ((k = 0; k < nmax; ++k)); do
      echo "share $k: $(atoms "c.alone$k") particles, loop alone $(loop_s "c.alone$k") s, beside the others $(loop_s "c.copy$k") s"
    done
    for ((k = 0; k < nmax; ++k)); do echo "$(loop_s "c.alone$k") $(loop_s "c.copy$k")"; done | awk '
      { a += $1; t += $2; if ($2 > m) m = $2 } END {
      printf "alone / beside the others: %.4g / %.4g s = %.3f (summed over the shares: the efficiency the machine allows this work on these cores; slowest share beside the others %.4g s)\n",
        a, t, a / t, m }'
    # from the last start to the first end all ran (start-up and reading included)
    for ((k = 0; k < nmax; ++k)); do cat "$out/c.copy$k.span"; done | awk '
      NR == 1 || $1 > t0 { t0 = $1 } NR == 1 || $2 < t1 { t1 = $2 } { s += $2 - $1 } END {
      printf "all shares running together: %.3g s of the %.3g s each ran (start to exit, mean)\n",
        (t1 > t0 ? t1 - t0 : 0), s / NR }'
  } > "$out/contention.txt"
fi
cat "$out"/*_discharge.screen "$out"/granary_balance.screen "$out"/contention.txt 2> /dev/null || true
