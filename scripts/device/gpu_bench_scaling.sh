#!/usr/bin/env bash
# The committed bench-scaling-gpu.json's rows (pathbench-bench --preset scaling: time against
# triangle count, spp and resolution), on the GPU host. Its 30 pixel and wavefront rows took
# 350 s on an H100 at 80b7e2b (each scaling:N scene is built again for each of 3 iterations),
# too long for one device call beside a build, so it runs in parts: FILTER picks rows by regex
# (e.g. 'gpu/pixel/' and 'gpu/(wavefront|paper-queue)/'), and the parts' JSON are merged on the
# development host (tools/merge_bench_json.py). Builds pathbench-bench into build-gpu if it is not
# there (a call after run_on_device.sh on a warm machine finds it).
#   scripts/device/gpu_bench_scaling.sh OUT_DIR NAME FILTER
# Writes OUT_DIR/bench-scaling-NAME.json, its console (.txt) and the GPU's state before and after.
set -uo pipefail
usage="usage: scripts/device/gpu_bench_scaling.sh OUT_DIR NAME FILTER"
if [ $# -ne 3 ] || [ -z "$1" ] || [ -z "$3" ]; then echo "$usage" >&2; exit 2; fi
out=$1; name=$2; filter=$3
[[ $name =~ ^[A-Za-z0-9_-]+$ ]] || { echo "gpu_bench_scaling.sh: NAME '$name': letters, digits, - and _ only" >&2; exit 2; }
mkdir -p "$out" && out=$(realpath "$out")
cd "$(dirname "${BASH_SOURCE[0]}")/../.." || exit 1
# shellcheck disable=SC1091  # made on the development host (../shared/gpu-host/README.md)
if [ -f .gpu-deps/unpack.sh ]; then source .gpu-deps/unpack.sh > /dev/null; fi
export PATH=$PATH:/usr/local/cuda/bin
if [ -f .gpu-deps/source-commit ]; then PATHBENCH_SOURCE_COMMIT=$(cat .gpu-deps/source-commit); export PATHBENCH_SOURCE_COMMIT; fi
if [ ! -x build-gpu/bin/pathbench-bench ]; then
  { cmake -S . -B build-gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
      -DCMAKE_CUDA_ARCHITECTURES=90 && cmake --build build-gpu -j "$(nproc)" --target pathbench-bench; } \
    > "$out/build-$name.log" 2>&1 || { echo "gpu_bench_scaling.sh: the build failed (build-$name.log)" >&2; exit 1; }
fi
state() { nvidia-smi --query-gpu=name,driver_version,temperature.gpu,clocks.sm,clocks_event_reasons.active --format=csv > "$1" 2>&1; }
state "$out/gpu-state-$name-start.csv"
PATHBENCH_SCALING_MAX=1000000 build-gpu/bin/pathbench-bench --preset scaling --benchmark_filter="$filter" \
  --benchmark_out="$out/bench-scaling-$name.json" --benchmark_out_format=json > "$out/bench-scaling-$name.txt" 2>&1
rc=$?
state "$out/gpu-state-$name-end.csv"
echo "scaling $name rc=$rc at ${SECONDS}s: $(grep -c manual_time "$out/bench-scaling-$name.txt") rows, $(grep -ci error "$out/bench-scaling-$name.txt") with an error"
exit $rc
