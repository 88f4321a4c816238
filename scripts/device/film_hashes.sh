#!/usr/bin/env bash
# Hashes of GPU films for a fixed set of renders (each strategy, float and double, both
# triangle tests, variance on and off), to check that a refactor leaves them
# bit-identical: run it on the tree before and after, and diff the two outputs.
# Usage: scripts/device/film_hashes.sh [build-dir] > hashes.txt   (needs a CUDA build and a GPU)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
pb=${1:-build-gpu}/bin/pathbench
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run() {  # name, then render options
  local name=$1
  shift
  "$pb" render --device gpu --quiet --out "$tmp/$name.pfm" --variance-out "$tmp/$name-var.pfm" "$@"
  echo "$name $(sha256sum < "$tmp/$name.pfm" | cut -c1-16) $(sha256sum < "$tmp/$name-var.pfm" | cut -c1-16)"
}
for strategy in pixel wavefront paper-queue; do
  run "paper-$strategy" --scene paper-cornell --width 256 --height 256 --spp 64 --strategy $strategy --sampling uniform
  run "box-nee-$strategy" --scene cornell-box --width 128 --height 128 --spp 32 --strategy $strategy --bounces 5
  run "box-rr-$strategy" --scene cornell-box --width 96 --height 96 --spp 16 --strategy $strategy --converged
done
run pixel-double --scene cornell-box --width 96 --height 96 --spp 16 --precision double
run pixel-mt --scene cornell-box --width 96 --height 96 --spp 16 --no-watertight
