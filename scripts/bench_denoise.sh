#!/bin/sh
# A benchmark of the denoiser (prints figures, asserts nothing; docs/denoising.md records
# them): regenerates the tuning and evaluation scenes (bench/denoise_scenes.py, deterministic
# by seed) into BUILD/denoise-scenes, then per set prints `keithray_bench_denoise goals` at
# SIZE x SIZE against REFERENCE_SPP-spp references (relMSE of the final filter at 16 spp
# against raw at 256 and 1,024 spp and against raw at the file's spp, and the medians), and
# the filters' cost at 512x512 on 2 threads. The renders are kept in BUILD/denoise-cache, so
# a rerun only filters.
# Usage: scripts/bench_denoise.sh [SIZE [REFERENCE_SPP [SET...]]]
#   SET: tune, eval, res (the eight path-traced scenes of docs/denoising.md), cost; default all.
#   KR_BUILD: the build folder (default build; it builds keithray_bench_denoise there).
set -eu
cd "$(dirname "$0")/.."
size=${1:-128}
reference=${2:-2048}
shift $(($# < 2 ? $# : 2))
sets=${*:-tune eval res cost}
build=${KR_BUILD:-build}
cmake --build "$build" --target keithray_bench_denoise >/dev/null
python3 bench/denoise_scenes.py "$build/denoise-scenes" --size "$size"
export KR_BENCH_CACHE="$build/denoise-cache" OMP_NUM_THREADS=2
mkdir -p "$KR_BENCH_CACHE"
for set in $sets; do
    echo "== $set"
    case $set in
    tune | eval) "$build/keithray_bench_denoise" goals "$size" "$reference" "$build/denoise-scenes/${set}_"*.json ;;
    # Their files ask for up to 4,096 spp: the comparison at the file's spp is capped at 1,024
    # (the cost of the renders).
    res) KR_BENCH_MAX_FILE_SPP=1024 "$build/keithray_bench_denoise" goals "$size" "$reference" \
        res/scenes/assignment_0[34568].json res/scenes/examples/denoise_dof.json \
        res/scenes/examples/denoise_caustics.json res/scenes/examples/denoise_many_lights.json ;;
    cost) OMP_WAIT_POLICY=passive "$build/keithray_bench_denoise" cost 15 res/scenes/assignment_03.json 3 ;;
    *) echo "scripts/bench_denoise.sh: unknown set '$set' (expected tune, eval, res or cost)" >&2; exit 2 ;;
    esac
done
