#!/usr/bin/env bash
# The reference machines' call on the GPU host (issue 28, item 4): one `run` of the device tool.
# Builds pathbench with CUDA, then, as long as time is left (BUDGET seconds in all):
#   1. the full suite on the GPU (recorded, page written),
#   2. the paper-frame benchmarks on the GPU and on the CPU (pathbench bench --preset paper,
#      9 repetitions, 1 s of frames each for NVML's energy window),
#   3. the suite on the host's CPU: full if time allows, else --quick.
# Everything lands in OUT: the history's text export (runs/), the pages, the bench JSON, logs.
#   tools/suite/device_run.sh OUT [BUDGET] [MACHINE_NAME]
# Needs .gpu-deps (sourced by the caller) and the suite's meshes packed by
# scripts/pack-suite-data.sh into suite-data/ beside this tree's root.
set -uo pipefail
out=${1:?usage: device_run.sh OUT [BUDGET] [MACHINE]}
budget=${2:-560}
machine=${3:-}  # default: the history names it by its CPU (intel-r-xeon-r...)
name=(); [ -n "$machine" ] && name=(--machine "$machine")
start=$(date +%s)
left() { echo $((budget - ($(date +%s) - start))); }
mkdir -p "$out"
out=$(realpath "$out")
cd "$(dirname "${BASH_SOURCE[0]}")/../.." || exit 1
export PATH=$PATH:/usr/local/cuda/bin
export PATHBENCH_DATA_DIR=/tmp/pathbench-data XDG_DATA_HOME=/tmp/pathbench-xdg PYTHONUNBUFFERED=1
log=$out/device-log.txt
echo "== $(date -u +%T) start, budget ${budget}s, source ${PATHBENCH_SOURCE_COMMIT:-?}" | tee -a "$log"
nvidia-smi > "$out/nvidia-smi.txt" 2>&1
lscpu > "$out/lscpu.txt" 2>&1
if [ -x suite-data/unpack.sh ]; then suite-data/unpack.sh >> "$log" 2>&1; echo "meshes rc=$?" | tee -a "$log"; fi
cmake -S . -B /tmp/build-gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
  -DCMAKE_CUDA_ARCHITECTURES=90 > "$out/build.txt" 2>&1 &&
  cmake --build /tmp/build-gpu -j 16 --target pathbench pathbench-bench >> "$out/build.txt" 2>&1
echo "== $(date -u +%T) build rc=$? ($(left)s left)" | tee -a "$log"
PB=/tmp/build-gpu/bin/pathbench
db=/tmp/pathbench-ref.sqlite
runs=$out/runs
$PB --version | tee -a "$log"
timeout $(($(left) - 20)) $PB suite --devices gpu "${name[@]}" --db $db --export "$runs" \
  --out "$out/suite-gpu" 2>&1 | tr '\r' '\n' | grep -v '^\[#*\.*\] ' >> "$log"
echo "== $(date -u +%T) suite gpu rc=${PIPESTATUS[0]} ($(left)s left)" | tee -a "$log"
for dev in gpu cpu; do
  [ "$(left)" -gt 90 ] || break
  timeout $(($(left) - 30)) $PB bench --preset paper --repetitions 9 --benchmark_filter="render/$dev/" \
    --benchmark_min_time=1 --out "$out/bench-paper-$dev.json" > "$out/bench-paper-$dev.txt" 2>&1
  echo "== $(date -u +%T) paper bench $dev rc=$? ($(left)s left)" | tee -a "$log"
  [ -f "$out/bench-paper-$dev.json" ] && $PB history record --db $db --export "$runs" "${name[@]}" \
    "$out/bench-paper-$dev.json" >> "$log" 2>&1
done
mode=()
[ "$(left)" -gt 300 ] || mode=(--quick)
if [ "$(left)" -gt 60 ]; then
  timeout $(($(left) - 10)) $PB suite --devices cpu "${mode[@]}" "${name[@]}" --db $db --export "$runs" \
    --out "$out/suite-cpu" 2>&1 | tr '\r' '\n' | grep -v '^\[#*\.*\] ' >> "$log"
  echo "== $(date -u +%T) suite cpu ${mode[*]} rc=${PIPESTATUS[0]} ($(left)s left)" | tee -a "$log"
fi
tail -n 60 "$log"
# At most 8 files come back: the log and one tarball of the rest.
(cd "$out" && cp device-log.txt device-log.keep && tar czf results.tar.gz --exclude=device-log.keep --exclude=results.tar.gz . &&
  find . -mindepth 1 -maxdepth 1 ! -name results.tar.gz ! -name device-log.keep -exec rm -rf {} + && mv device-log.keep device-log.txt)
ls -la "$out"
