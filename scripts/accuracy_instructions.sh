#!/usr/bin/env bash
# The cost side of the precision and intersection comparisons of `pathbench accuracy`,
# free of machine load: instructions per sample counted by callgrind, for float and
# double path steps and Embree's watertight (robust, Pluecker) and Moeller-Trumbore
# (fast) tests. Per configuration: (instructions at 17 spp - at 1 spp) / (16 x pixels),
# one thread, 32x32, unbounded paths with Russian roulette and light sampling, so start-up
# and the Embree build cancel out. Writes results/<machine>/accuracy/instructions-per-sample.md.
# Needs valgrind and a built build/bin/pathbench; about 4 minutes.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
exe=build/bin/pathbench
machine=$(.venv/bin/python -c 'import sys; sys.path.insert(0, "tools"); import machine; print(machine.machine_slug())' 2>/dev/null ||
          python3 -c 'import sys; sys.path.insert(0, "tools"); import machine; print(machine.machine_slug())')
out=results/$machine/accuracy/instructions-per-sample.md
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
w=32
configs=("float, watertight:--precision float --watertight"
         "double, watertight:--precision double --watertight"
         "float, Moeller-Trumbore:--precision float --no-watertight")
# --embree-layout triangles: a fixed layout, as when these figures were first taken (auto
# times a probe in each process, and under valgrind its timing means little); the
# comparisons here are between precisions and ray/triangle tests, in one layout.
instructions() {  # scene, spp, args...
  local scene=$1 spp=$2
  shift 2
  valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" "$exe" render --scene "$scene" --width $w --height $w \
    --spp "$spp" --converged --sampling nee --threads 1 --embree-layout triangles --quiet "$@" >/dev/null 2>"$tmp/cg.err"
  awk '/^summary:/ {print $2}' "$tmp/cg.out"
}
{
  echo "# Instructions per sample (callgrind): precision and ray/triangle test"
  echo
  echo "| scene | path step, intersection | instructions per sample | against float, watertight |"
  echo "|---|---|---:|---:|"
  for scene in paper-cornell cornell-box; do
    base=""
    for cfg in "${configs[@]}"; do
      label=${cfg%%:*}
      read -r -a args <<<"${cfg#*:}"
      a=$(instructions "$scene" 1 "${args[@]}")
      b=$(instructions "$scene" 17 "${args[@]}")
      per=$(( (b - a) / (16 * w * w) ))
      [[ -z $base ]] && base=$per
      echo "| $scene | $label | $per | $(awk -v p="$per" -v q="$base" 'BEGIN {printf "%.3f", p / q}') |"
    done
  done
  echo
  echo "- $w x $w, unbounded paths with Russian roulette, light sampling + MIS, pixel strategy, one thread;"
  echo "  (instructions at 17 spp - at 1 spp) / (16 x pixels), so start-up and the Embree build cancel out."
  echo "  Every configuration traces the same rays (same seed), so this is the cost per sample of the path"
  echo "  step's scalar type and of the ray/triangle test alone. Instruction counts do not depend on machine"
  echo "  load; wall-clock times are in the accuracy tables beside this file."
  echo "- $(valgrind --version), git $(git rev-parse --short=12 HEAD), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')."
  echo "- Made by scripts/accuracy_instructions.sh."
} >"$out.tmp"
mv "$out.tmp" "$out"
cat "$out"
