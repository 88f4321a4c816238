#!/usr/bin/env bash
# Where a GPU kernel's instructions go, SASS instruction by SASS instruction: Nsight
# Compute's source counters (executed instructions, thread-level executed instructions and
# sampled warp stalls per SASS address) for the pixel megakernel on paper-cornell and the
# raw incoherent closest-hit ray casts on the same scene. Runs on the GPU host, after
# scripts/device/run_on_device.sh's build (BUILD_DIR/bin/pathbench, pathbench-bench);
# tools/sass_profile.py turns the SASS CSV into tables by opcode and by hot block. (The
# source page's CUDA view is not exported: with -lineinfo it gave only the kernel's own file,
# without counts.)
#   scripts/device/gpu_sass_profile.sh BUILD_DIR OUT_DIR
# --clock-control none as in scripts/device/gpu_roofline.sh. One launch per kernel, after the first
# (a render's first launch is its warm-up frame, one sample a pixel, whose warps span 32
# pixels; the bench's is its warm-up): the counts are per launch (pixel: 256x256 x SPP
# samples; ray casts: the bench's stored rays). SKIP=0 profiles the first launch instead.
# With NAME KERNEL_REGEX -- COMMAND... after OUT_DIR, it profiles that one kernel of that
# command instead (e.g. k_wf_shade of a wavefront render, SKIP=21: a launch mid-frame), and
# tools/sass_profile.py then writes NAME-profile.txt (by opcode, hot blocks, and the most
# stalled instructions with their reasons).
#   scripts/device/gpu_sass_profile.sh BUILD_DIR OUT_DIR [NAME KERNEL_REGEX -- COMMAND...]
set -uo pipefail
usage="usage: scripts/device/gpu_sass_profile.sh BUILD_DIR OUT_DIR [NAME KERNEL_REGEX -- COMMAND...]"
build=${1:?$usage}
out=${2:?$usage}
shift 2
if [ $# -gt 0 ] && { [ $# -lt 4 ] || [ "$3" != "--" ]; }; then echo "$usage" >&2; exit 2; fi
spp=${SPP:-16}
mkdir -p "$out"
sections=(--section SourceCounters --section WarpStateStats --section InstructionStats --section LaunchStats
          --section Occupancy --section ComputeWorkloadAnalysis --section SpeedOfLight)
profile() {  # name, kernel regex, then the command
  local name=$1 kernel=$2; shift 2
  echo "== $name"
  timeout 300 ncu --clock-control none --import-source yes "${sections[@]}" -k "regex:$kernel" \
    --launch-skip "${SKIP:-1}" --launch-count 1 \
    -f -o "$out/$name" "$@" > "$out/$name.log" 2>&1
  echo "profile rc=$?"
  ncu -i "$out/$name.ncu-rep" --page source --csv --print-source sass > "$out/$name-sass.csv" 2> "$out/$name-sass.err"
  echo "sass page rc=$? $(wc -l < "$out/$name-sass.csv") lines"
  ncu -i "$out/$name.ncu-rep" --page details --csv > "$out/$name-details.csv" 2> "$out/$name-details.err"
  echo "details rc=$? $(wc -l < "$out/$name-details.csv") lines"
  python3 "$(dirname "${BASH_SOURCE[0]}")/../../tools/sass_profile.py" "$out/$name-sass.csv" --top 30 --stalls 20 \
    > "$out/$name-profile.txt" 2>&1
  echo "sass_profile rc=$?"
}
if [ $# -gt 0 ]; then  # one kernel of the caller's command
  name=$1 kernel=$2
  shift 3
  profile "$name" "$kernel" "$@"
  exit 0
fi
profile pixel k_pixel "$build/bin/pathbench" render --device gpu --quiet --scene paper-cornell --width 256 --height 256 \
  --spp "$spp" --bounces 2 --sampling nee --strategy pixel
profile raycast k_trace "$build/bin/pathbench-bench" --preset paper \
  --benchmark_filter='^raycast/gpu/closest/incoherent/paper-cornell$'
