#!/usr/bin/env bash
# `pathbench crosscheck` (pathbench against Mitsuba 3, per pixel) over every built-in
# scene and every example scene file, on the CPU and, where one can run, the GPU
# (--device all). One line per scene in OUT_DIR/summary.txt, each scene's images and
# verdict.json under OUT_DIR/<scene>/; exit 1 when any scene fails.
#   scripts/crosscheck_all.sh PATHBENCH OUT_DIR [crosscheck options, e.g. --spp 64]
# Needs Mitsuba 3 in the Python that crosscheck runs (.venv, or PATHBENCH_PYTHON).
set -uo pipefail
pb=${1:?usage: scripts/crosscheck_all.sh PATHBENCH OUT_DIR [options]}
out=${2:?usage: scripts/crosscheck_all.sh PATHBENCH OUT_DIR [options]}
shift 2
cd "$(dirname "${BASH_SOURCE[0]}")/.."
mkdir -p "$out"
scenes=(paper-cornell cornell-box cornell-box:mirror cornell-box:glass cornell-box:spheres cornell-box:ggx
        "furnace:0.5" "paper-cornell-ico:2" "scaling:1000"
        scenes/examples/instancing.json scenes/examples/mitsuba-box.xml scenes/examples/pyramids.gltf
        scenes/boxes.obj scenes/materials-example.json scenes/mesh-example.json)
failed=0
: > "$out/summary.txt"
for s in "${scenes[@]}"; do
  dir="$out/$(basename "$s" | tr ':/' '__')"
  start=$(date +%s)
  "$pb" crosscheck "$s" --device all --out-dir "$dir" "$@" > "$dir.log" 2>&1
  status=$?
  [ $status = 0 ] || failed=1
  verdicts=$(grep -E "PASS|FAIL" "$dir.log" | tr '\n' ' ')
  echo "$s: exit $status, $(( $(date +%s) - start )) s: ${verdicts:-$(tail -2 "$dir.log" | tr '\n' ' ')}" | tee -a "$out/summary.txt"
done
exit $failed
