#!/usr/bin/env bash
# The speed/accuracy study (docs/user-guide.md, "Speed against accuracy"): builds, then runs
# `pathbench accuracy` on paper-cornell and cornell-box at 128x128 on the CPU, and on the
# GPU where there is one. References are cached in the output folder (pathbench-out/<machine>/accuracy/;
# with --update-committed, the committed results/<machine>/accuracy/), so a
# re-run (on a quiet machine, for clean times) renders only the sweep. Extra arguments
# go to every `pathbench accuracy` call (e.g. --max-seconds 40).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
scripts/install-deps.sh
scripts/build.sh
devices=(cpu)
if build/bin/pathbench render --device gpu --width 1 --height 1 --spp 1 --quiet >/dev/null 2>&1; then devices+=(gpu); fi
for device in "${devices[@]}"; do
  for scene in paper-cornell cornell-box; do
    echo "load average before ${scene} on ${device}: $(cut -d' ' -f1-3 /proc/loadavg)"
    build/bin/pathbench accuracy --scene "$scene" --device "$device" --width 128 --height 128 "$@"
  done
done
