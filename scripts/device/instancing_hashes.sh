#!/usr/bin/env bash
# --instancing on the GPU (issue 16 item 2): for each instanced test scene, strategy and
# device, the film hash with --instancing off and on (the report's film_hash), and whether
# they match. The GPU's must match everywhere (two_level_bvh.h); the CPU's match but for
# rare rays meeting a copy's edge (docs/notes/cpu-log.md). Prints "device strategy scene off on same|DIFF"
# and exits 1 if a GPU line differs.
# Usage: scripts/device/instancing_hashes.sh [build-dir] [WxHxSPP]   (needs a CUDA build and a GPU)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
pb=${1:-build-gpu}/bin/pathbench
IFS=x read -r w h spp <<< "${2:-256x192x16}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 scenes/make_instance_grid.py "$tmp/grid" --n 10 --subdiv 3 >/dev/null  # 1000 copies
scenes=(scenes/examples/instancing.json tests/data/scenes/instances/grid-125.json "$tmp/grid/grid-1000.json"
        tests/data/scenes/formats/instanced.xml tests/data/scenes/formats/instanced.gltf scenes/examples/pyramids.gltf)
hash_of() { python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(r["film_hash"], r["instancing"]["used"], r["instancing"]["accel_bytes"])' "$1"; }
bad=0
for device in gpu cpu; do
  strategies="pixel wavefront"
  [[ $device == gpu ]] && strategies="pixel wavefront paper-queue"
  for strategy in $strategies; do
    for scene in "${scenes[@]}"; do
      for m in off on; do
        "$pb" render --scene "$scene" --device $device --strategy $strategy --width "$w" --height "$h" --spp "$spp" \
          --instancing $m --quiet --report "$tmp/$m.json" 2>/dev/null
      done
      read -r a _ bytes_off <<< "$(hash_of "$tmp/off.json")"
      read -r b used bytes_on <<< "$(hash_of "$tmp/on.json")"
      same=same; [[ $a == "$b" ]] || same=DIFF
      [[ $device == gpu && $same == DIFF ]] && bad=1
      echo "$device $strategy $(basename "$scene") $a $b $same (instanced: $used, accel bytes $bytes_off -> $bytes_on)"
    done
  done
done
exit $bad
