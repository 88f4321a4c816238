#!/usr/bin/env bash
# Per-kernel roofline figures of the GPU tracer from Nsight Compute's hardware counters:
# for each kernel of the pixel, wavefront and paper-queue strategies on paper-cornell
# (and the pixel megakernel on paper-cornell-ico:8), the achieved instruction issue rate
# and memory throughput against the device's peaks. Runs on the GPU host (ncu there reads
# the counters); tools/roofline.py turns the CSV into JSON, a table and a plot.
#   scripts/device/gpu_roofline.sh BUILD_DIR OUT_DIR
# --clock-control none: the clocks stay as the benchmarks see them (METHOD.md); each
# kernel launch is replayed by ncu, so the frames are small (the rates per kernel are
# what counts, not the frame time) and at most LAUNCHES launches are profiled per run.
# ROOFLINE_ONLY=REGEX runs only the runs whose name matches. ROOFLINE_RUNS=FILE adds runs, one a
# line: "name | VAR=value ... | pathbench render arguments" (the variables set for that run
# alone, "-" for none), e.g. one kernel at two occupancies by PATHBENCH_GPU_PIXEL_BLOCKS.
set -uo pipefail
build=${1:?usage: scripts/device/gpu_roofline.sh BUILD_DIR OUT_DIR}
out=${2:?usage: scripts/device/gpu_roofline.sh BUILD_DIR OUT_DIR}
launches=${LAUNCHES:-40}
mkdir -p "$out"
metrics=gpu__time_duration.sum,sm__cycles_elapsed.avg.per_second,sm__inst_executed.sum,\
sm__inst_issued.avg.pct_of_peak_sustained_active,sm__inst_issued.avg.per_cycle_active,\
sm__throughput.avg.pct_of_peak_sustained_elapsed,gpu__compute_memory_throughput.avg.pct_of_peak_sustained_elapsed,\
dram__throughput.avg.pct_of_peak_sustained_elapsed,dram__bytes.sum,lts__t_sectors.avg.pct_of_peak_sustained_elapsed,\
l1tex__t_sectors.avg.pct_of_peak_sustained_elapsed,sm__warps_active.avg.pct_of_peak_sustained_active,\
smsp__thread_inst_executed_per_inst_executed.ratio,launch__registers_per_thread
run() {  # name, then pathbench render arguments
  local name=$1; shift
  [[ -n ${ROOFLINE_ONLY:-} && ! $name =~ ${ROOFLINE_ONLY} ]] && return  # ROOFLINE_ONLY=REGEX: those runs alone
  echo "== $name"
  timeout 300 ncu --clock-control none --csv --print-units base --metrics "$metrics" --launch-count "$launches" \
    "$build/bin/pathbench" render --device gpu --quiet "$@" > "$out/$name.csv" 2> "$out/$name.err"
  echo "rc=$? $(grep -c '"' "$out/$name.csv") csv lines"
}
common=(--width 256 --height 256 --bounces 2 --sampling nee)
run paper-cornell-pixel --scene paper-cornell --strategy pixel --spp 64 "${common[@]}"
run paper-cornell-wavefront --scene paper-cornell --strategy wavefront --spp 16 "${common[@]}"
run paper-cornell-paper-queue --scene paper-cornell --strategy paper-queue --spp 16 "${common[@]}"
run ico8-pixel --scene paper-cornell-ico:8 --strategy pixel --spp 16 "${common[@]}"
# Issue 32: the same megakernel on the wide BVH (ico8-pixel: the layout auto picks, binary).
PATHBENCH_GPU_BVH=wide8 run ico8-wide8-pixel --scene paper-cornell-ico:8 --strategy pixel --spp 16 "${common[@]}"
if [ -n "${ROOFLINE_RUNS:-}" ]; then
  while IFS='|' read -r name vars args; do
    read -r name <<< "$name"
    [[ -z $name || $name == \#* ]] && continue
    # shellcheck disable=SC2086  # the variables and arguments are words
    (for v in $vars; do [ "$v" = - ] || export "${v?}"; done; run "$name" $args)
  done < "$ROOFLINE_RUNS"
fi
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem,power.limit --format=csv > "$out/nvidia-smi.csv"
