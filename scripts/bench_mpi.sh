#!/usr/bin/env bash
# Figures for docs/scaling.md: keithray under mpirun on this machine.
#   ratio:   1 process of 2 threads against mpirun -np 1 and -np 2 of 1 thread each, on one
#            scene, interleaved, REPEATS rounds; prints each run's seconds and the medians' ratios.
#   exchange: the per-pass statistics exchange alone (bench/mpi_exchange.cpp, built
#            here with mpicxx) at 512x512 and 3840x2160, 2 and 4 ranks.
#   balance: mpirun -np 4 (oversubscribed, 1 thread each) on scenes 3, 6 and 8 at their own
#            spp; prints keithray's per-rank summary (busy CPU seconds, slowest vs mean).
#   plan:    adaptive against uniform allocation under mpirun -np 1, 2 and 4 (1 thread each),
#            scene 6 at 512x512, 64 spp, interleaved, REPEATS rounds: each run's wall seconds,
#            and per pass after which the statistics were exchanged, what the busiest rank
#            spent exchanging and planning (keithray's per-rank summary) and the bytes a rank
#            received. With BASELINE=path/to/another/keithray, that build's runs are
#            interleaved with these (its summary names no bytes: 36 B x P x (N-1)/N a pass).
#   memory:  each rank's peak resident memory (/usr/bin/time) in a 4096x4096 render (scene 1,
#            10 spp: adaptive allocation plans passes 9 and 10) at np 1, 2 and 4.
#   view:    `keithray view` (under xvfb-run) in one process and under mpirun -np 1, 2 and 4
#            (1 thread a rank), scene 6 at 512x512, interleaved, REPEATS rounds: the edit to
#            first preview latency (--measure-latency 10: orbit nudges made while full passes
#            run) and full passes per second of the render thread (32 passes, --denoise off:
#            spp over the stats' elapsed seconds, previews and the gathers included); medians.
# Usage: scripts/bench_mpi.sh ratio|balance|exchange|plan|memory|view [REPEATS] [extra flags]
set -euo pipefail
cd "$(dirname "$0")/.."
exe=build/keithray
what=${1:-ratio}
repeats=${2:-3}
shift $(( $# > 2 ? 2 : $# ))
root=()
[ "$(id -u)" = 0 ] && root=(--allow-run-as-root)
mpi=(mpirun --oversubscribe --bind-to none "${root[@]}" -x OMP_NUM_THREADS=1 -x OMP_WAIT_POLICY=passive)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

seconds() { sed -n 's/.* spp, \([0-9.]*\) s,.*/\1/p' | head -1; }
median() { sort -g | awk '{v[NR]=$1} END {print NR == 0 ? "-" : (NR % 2) ? v[(NR+1)/2] : (v[NR/2] + v[NR/2+1]) / 2}'; }

case $what in
ratio)
  scene=res/scenes/assignment_03.json
  : >"$out/threads2"; : >"$out/np1"; : >"$out/np2"
  for ((i = 0; i < repeats; i++)); do
    OMP_WAIT_POLICY=passive "$exe" render "$scene" -q --threads 2 -o "$out/a.ppm" "$@" | seconds >>"$out/threads2"
    "${mpi[@]}" -np 1 "$exe" render "$scene" -q -o "$out/b.ppm" "$@" | seconds >>"$out/np1"
    "${mpi[@]}" -np 2 "$exe" render "$scene" -q -o "$out/c.ppm" "$@" | seconds >>"$out/np2"
    cmp -s "$out/a.ppm" "$out/c.ppm" || { echo "bench_mpi: -np 2 image differs from one process's" >&2; exit 1; }
  done
  t2=$(median <"$out/threads2"); n1=$(median <"$out/np1"); n2=$(median <"$out/np2")
  echo "scene $scene $*, $repeats rounds interleaved; seconds per run:"
  echo "  1 process x 2 threads: $(tr '\n' ' ' <"$out/threads2") median $t2"
  echo "  mpirun -np 1 x 1 thread: $(tr '\n' ' ' <"$out/np1") median $n1"
  echo "  mpirun -np 2 x 1 thread: $(tr '\n' ' ' <"$out/np2") median $n2"
  awk -v t2="$t2" -v n1="$n1" -v n2="$n2" 'BEGIN {
    printf "  np 2 / threads 2 time: %.3f; speed-up np 1 -> np 2: %.2f\n", n2 / t2, n1 / n2 }'
  ;;
balance)
  for n in 3 6 8; do
    echo "scene $n, mpirun -np 4 (1 thread each) $*:"
    "${mpi[@]}" -np 4 "$exe" render res/scenes/assignment_0$n.json -q -o "$out/s$n.ppm" "$@"
  done
  ;;
exchange)
  mpicxx -O2 -o "$out/exchange" bench/mpi_exchange.cpp
  for n in 2 4; do
    for size in "512 512" "3840 2160"; do "${mpi[@]}" -np $n "$out/exchange" $size; done
  done
  ;;
plan)
  exes=("$exe")
  [ -n "${BASELINE:-}" ] && exes=("$BASELINE" "$exe")
  # One run: its wall seconds, then per exchanged pass: exchange ms, plan ms, MB received.
  run() {
    local binary=$1 np=$2 alloc=$3
    shift 3
    "${mpi[@]}" -np "$np" "$binary" render res/scenes/assignment_06.json -q --spp 64 --allocation "$alloc" \
      -o "$out/p.ppm" "$@" |
      awk '/ spp, / { for (i = 1; i <= NF; i++) if ($(i + 1) == "s,") t = $i }
           /ranks: busy/ { for (i = 1; i <= NF; i++) {
               if ($i == "exchange") x = $(i + 1); if ($i == "MB") mb = $(i - 1)
               if ($i == "after") n = $(i + 1); if ($i == "between") b = $(i + 2) } }
           END { if (n > 0) printf "%s %.2f %.2f %s\n", t, 1000 * x / n, 1000 * b / n, mb == "" ? "-" : mb / n
                 else printf "%s - - -\n", t }'
  }
  for ((i = 0; i < repeats; i++)); do
    for n in 1 2 4; do
      for alloc in adaptive uniform; do
        for e in "${!exes[@]}"; do
          run "${exes[$e]}" $n $alloc "$@" >>"$out/plan-$e-$n-$alloc"
        done
      done
    done
  done
  echo "scene 6, 512x512, 64 spp, $repeats rounds interleaved; medians (per exchanged pass: busiest rank)"
  echo "build | np | allocation | wall s | exchange ms | plan + noise ms | MB received"
  for e in "${!exes[@]}"; do
    for n in 1 2 4; do
      for alloc in adaptive uniform; do
        f="$out/plan-$e-$n-$alloc"
        col() { awk -v c="$1" '{print $c}' "$f" | grep -v '^-$' | median; }
        echo "$([ ${#exes[@]} = 2 ] && [ "$e" = 0 ] && echo baseline || echo this) | $n | $alloc | $(col 1) | $(col 2) | $(col 3) | $(col 4)"
      done
    done
  done
  ;;
memory)
  sed 's/"dimensions" : \[512, 512\]/"dimensions" : [4096, 4096]/' res/scenes/assignment_01.json >"$out/big.json"
  for n in 1 2 4; do
    echo "np $n (rank order not kept), peak resident kB:"
    "${mpi[@]}" -np $n /usr/bin/time -f "  %M" "$exe" render "$out/big.json" --spp 10 -q -o "$out/big.ppm" "$@" 2>&1 |
      grep -E '^  [0-9]+$|ranks: busy'
  done
  ;;
view)
  scene=res/scenes/assignment_06.json
  runs=(plain np1 np2 np4)
  for r in "${runs[@]}"; do : >"$out/view-$r"; done
  for ((i = 0; i < repeats; i++)); do
    for r in "${runs[@]}"; do
      launch=()
      [ "$r" != plain ] && launch=("${mpi[@]}" -np "${r#np}")
      xvfb-run -a -s '-screen 0 1280x1024x24 -noreset' "${launch[@]}" "$exe" view "$scene" --spp 32 --frames 32 \
        --measure-latency 10 --denoise off --stats-json "$out/stats.json" --timeout 600 "$@" >"$out/log" 2>/dev/null
      latency=$(sed -n 's/^latency .*edits: median \([0-9.]*\) ms.*/\1/p' "$out/log")
      python3 -c 'import json, sys; s = json.load(open(sys.argv[1])); print(sys.argv[2], "%.2f" % (s["spp"] / s["elapsed_seconds"]))' \
        "$out/stats.json" "$latency" >>"$out/view-$r"
    done
  done
  echo "scene 6, 512x512, $repeats rounds interleaved $*; per run: first-preview latency ms, full passes/s"
  for r in "${runs[@]}"; do
    echo "  $r: $(tr '\n' ';' <"$out/view-$r") medians $(awk '{print $1}' "$out/view-$r" | median) ms," \
      "$(awk '{print $2}' "$out/view-$r" | median) passes/s"
  done
  ;;
*) echo "usage: $0 ratio|balance|exchange|plan|memory|view [REPEATS] [flags]" >&2; exit 2 ;;
esac
