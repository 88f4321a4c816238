#!/usr/bin/env bash
# The reference machines' call on the GPU host (issue 28): one `run` of the device tool, from
# the root of this tree there. In BUDGET seconds (default 480) it
#   1. builds pathbench with CUDA (pathbench, pathbench-bench),
#   2. runs two lanes side by side, each pinned to its own cores (taskset):
#      GPU lane, cores 0-1: the full suite on the GPU (9 repetitions), then every workload's
#        GPU image against Mitsuba 3 `cuda_ad_rgb` (pathbench suite --crosscheck);
#      CPU lane, cores 2-15: the full suite on the CPU (its widest ISA, 14 threads), with
#        fewer repetitions for the slow full frames (--repetitions-for; the page says so),
#   3. tars the pages, bench JSON, crosscheck verdicts and logs into OUT (at most 8 files).
# Nothing is recorded into the project's history there: the bench JSON comes back and is
# recorded here with `pathbench history record --export results/history/runs`.
#   tools/suite/device_run.sh OUT [BUDGET]
# Needs: the Debian deps unpacked (source DEPS/unpack.sh first); SUITE_DATA: a folder from
# scripts/pack-suite-data.sh; MITSUBA_TAR (optional): Mitsuba 3 + Dr.Jit for Python 3.12
# (cuda_ad_rgb; ../shared/gpu-host/README.md), without which the crosscheck is skipped.
set -uo pipefail
out=${1:?usage: device_run.sh OUT [BUDGET]}
budget=${2:-480}
start=$(date +%s)
left() { echo $((budget - ($(date +%s) - start))); }
mkdir -p "$out"
out=$(realpath "$out")
cd "$(dirname "${BASH_SOURCE[0]}")/../.." || exit 1
export PATH=$PATH:/usr/local/cuda/bin
export PATHBENCH_DATA_DIR=/tmp/pathbench-data XDG_DATA_HOME=/tmp/pathbench-xdg PYTHONUNBUFFERED=1
log=$out/device-log.txt
say() { echo "== $(date -u +%T) $* ($(left)s left)" | tee -a "$log"; }
say "start, budget ${budget}s, source ${PATHBENCH_SOURCE_COMMIT:-?}"
nvidia-smi > "$out/nvidia-smi.txt" 2>&1
lscpu > "$out/lscpu.txt" 2>&1
[ -n "${SUITE_DATA:-}" ] && { "$SUITE_DATA/unpack.sh" >> "$log" 2>&1; say "meshes rc=$?"; }
mi=""
if [ -n "${MITSUBA_TAR:-}" ] && [ -f "$MITSUBA_TAR" ]; then
  mkdir -p /tmp/mitsuba && tar xJf "$MITSUBA_TAR" -C /tmp/mitsuba && mi=/tmp/mitsuba
  say "mitsuba unpacked: ${mi:-no}"
fi
cmake -S . -B /tmp/build-gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
  -DCMAKE_CUDA_ARCHITECTURES=90 > "$out/build.txt" 2>&1 &&
  cmake --build /tmp/build-gpu -j 16 --target pathbench pathbench-bench >> "$out/build.txt" 2>&1
say "build rc=$?"
# The deps' link-time names of Embree and pugixml shadow Mitsuba's own libembree3.so and
# libpugixml.so (LD_LIBRARY_PATH comes before its RUNPATH): pathbench, built, needs only the
# versioned names (libembree3.so.3, libpugixml.so.1).
rm -f /opt/deps/usr/lib/x86_64-linux-gnu/libembree3.so /opt/deps/usr/lib/x86_64-linux-gnu/libpugixml.so
PB=/tmp/build-gpu/bin/pathbench
$PB --version | tee -a "$log"
ncpu=$(nproc)
t_lanes=$(($(left) - 25))
# CPU lane: the cheap full frames with 9 repetitions, the slow ones with fewer (seconds per
# frame on this Xeon, estimated from the 2-core VM: glass-dragon ~30, cornell-materials ~12,
# large-mesh ~14, bunny-armadillo ~9; the others <= 4).
few=(--repetitions-for 'glass-dragon|cornell-materials=2' --repetitions-for 'bunny-armadillo|large-mesh=3')
[ "$t_lanes" -lt 330 ] && few=(--repetitions-for 'glass-dragon|cornell-materials|bunny-armadillo|large-mesh=1')
(
  timeout "$t_lanes" taskset -c 2-$((ncpu - 1)) $PB suite --devices cpu "${few[@]}" --db /tmp/suite-cpu.sqlite \
    --out "$out/suite-cpu" > "$out/suite-cpu.txt" 2>&1
  echo "== $(date -u +%T) suite cpu rc=$?" >> "$log"
) &
cpu_lane=$!
(
  timeout $((t_lanes - 120)) taskset -c 0-1 $PB suite --devices gpu --db /tmp/suite-gpu.sqlite \
    --out "$out/suite-gpu" > "$out/suite-gpu.txt" 2>&1
  echo "== $(date -u +%T) suite gpu rc=$?" >> "$log"
  if [ -n "$mi" ]; then
    # Mitsuba's Python (3.12 wheels) through the launcher's PYTHONPATH.
    PYTHONPATH=$mi${PYTHONPATH:+:$PYTHONPATH} timeout $(($(left) - 30)) taskset -c 0-1 $PB suite --crosscheck \
      --devices gpu --mitsuba-variant cuda_ad_rgb --crosscheck-size 64x64 --crosscheck-spp 256 \
      --out "$out/crosscheck-gpu" > "$out/crosscheck-gpu.txt" 2>&1
    echo "== $(date -u +%T) crosscheck gpu rc=$?" >> "$log"
  fi
) &
gpu_lane=$!
wait "$gpu_lane" "$cpu_lane"
say "lanes done"
tail -n 14 "$out/suite-gpu.txt" "$out/suite-cpu.txt" "$out/crosscheck-gpu.txt" 2>/dev/null
# A run cut short leaves its finished bench JSON in the suite's hidden work folder: keep it.
for d in "$out"/.suite-*.partial-*; do [ -d "$d" ] && mv "$d" "$out/partial-$(basename "$d" | tr -c 'a-zA-Z0-9_\n-' _)"; done
# At most 8 files, each under 16 MiB, come back: the log and one tarball of the rest, without the
# crosscheck's exported meshes and images (24 MB at 2cae000: the tarball did not come back).
(cd "$out" && tar czf /tmp/results.tar.gz --exclude='*.ply' --exclude='*.pfm' --exclude='*.obj' . &&
  find . -mindepth 1 -maxdepth 1 ! -name device-log.txt -exec rm -rf {} + && mv /tmp/results.tar.gz .)
ls -la "$out"
