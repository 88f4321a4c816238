#!/usr/bin/env bash
# Instructions per sample of the two CPU strategies (callgrind), free of machine load:
# paper-cornell 64x64, 16 spp, 2 bounces, nee, one thread, collection toggled on inside
# the diffuse-only float instantiation of each strategy (the render itself, not start-up
# or the Embree build). Both Embree layouts, pinned (--embree-layout auto times a probe,
# and under valgrind its timing means little). Prints "strategy/layout instructions
# instructions/sample".
# Usage: scripts/cpu_instructions.sh [build-dir] [keep-dir]  (keep-dir: keep callgrind.out.* for
# callgrind_annotate). Needs valgrind and a built <build-dir>/bin/pathbench.
# ISA=avx2|scalar pins `--isa` (valgrind 3.19 runs no AVX-512: under it, auto means avx2).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
exe=${1:-build}/bin/pathbench
keep=${2:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
w=64 spp=16
declare -A toggle=(
  [pixel]='pb::cpu::TraceTotals pb::cpu::render_pixel_parallel_for<float, 1u>(pb::cpu::TraceJob const&)'
  [wavefront]='pb::cpu::TraceTotals pb::cpu::render_wavefront_for<float, 1u>(pb::cpu::TraceJob const&, unsigned long)')
for strategy in pixel wavefront; do
  for layout in triangles quads; do
    out=$tmp/callgrind.out.$strategy.$layout
    valgrind --tool=callgrind --callgrind-out-file="$out" --toggle-collect="${toggle[$strategy]}" "$exe" render \
      --scene paper-cornell --width $w --height $w --spp $spp --bounces 2 --sampling nee --threads 1 \
      --strategy "$strategy" --embree-layout $layout ${ISA:+--isa $ISA} --quiet --out "$tmp/image.pfm" >/dev/null 2>"$tmp/cg.err"
    ir=$(awk '/^summary:/ {print $2}' "$out")
    echo "$strategy/$layout $ir $(awk -v i="$ir" -v n=$((w * w * spp)) 'BEGIN {printf "%.1f", i / n}')"
    [[ -n $keep ]] && cp "$out" "$keep/"
  done
done
