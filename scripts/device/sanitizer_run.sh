# shellcheck shell=bash
# Sourced by the device scripts (run_on_device.sh, gpu_binaries_ab.sh): one compute-sanitizer run.
#   sanitizer_run LOG TOOL PATHBENCH ARGS...
# runs `PATHBENCH render ARGS` under `compute-sanitizer --tool TOOL` (memcheck, racecheck, ...)
# into LOG and prints its exit status and the tool's summary line.
sanitizer_run() {
  local log=$1 tool=$2 pb=$3
  shift 3
  timeout 120 compute-sanitizer --tool "$tool" --print-limit 20 "$pb" render "$@" > "$log" 2>&1
  echo "rc=$? $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY' "$log")"
}
