#!/usr/bin/env bash
# BVH layouts and megakernel occupancies, interleaved, on one GPU host: each round runs
# every case once (one process each, CUDA-event device time of the frame after the
# warm-up frame), and keeps each film's hash. Unlike gpu_ab.sh (two builds, one set of
# settings), each case names its own build, so one call can set the layouts of one build
# side by side and against another build.
#   scripts/device/gpu_layout_sweep.sh CASES OUT_DIR [ROUNDS]
# CASES: a file of "name | BUILD_DIR | [VAR=value ...] pathbench render options" lines
# (VAR=value words at the front go to the environment, e.g. PATHBENCH_GPU_BVH=wide8).
# Prints per case the median device ms, every round's, the film hashes, and the report's
# BVH layout and pixel occupancy.
set -uo pipefail
cases=${1:?usage: scripts/device/gpu_layout_sweep.sh CASES OUT_DIR [ROUNDS]}
out=${2:?usage: scripts/device/gpu_layout_sweep.sh CASES OUT_DIR [ROUNDS]}
rounds=${3:-3}
mkdir -p "$out/films"
tsv="$out/sweep.tsv"
echo -e "round\tcase\tdevice_ms\tfilm_sha\tlayout\tblocks" > "$tsv"
for round in $(seq 1 "$rounds"); do
  while IFS='|' read -r name build opts; do
    name=${name//[[:space:]]/}
    build=${build//[[:space:]]/}
    [ -z "$name" ] && continue
    opts_env="" opts_args=""
    for w in $opts; do
      if [ -z "$opts_args" ] && [[ $w =~ ^[A-Z_][A-Z0-9_]*= ]]; then opts_env+=" $w"; else opts_args+=" $w"; fi
    done
    film="$out/films/$name.pfm"
    # shellcheck disable=SC2086
    timeout 300 env $opts_env "$build/bin/pathbench" render --device gpu --quiet $opts_args --out "$film" \
      --report "$out/r.json" > "$out/last.log" 2>&1 || { echo "$name failed: $(tail -2 "$out/last.log")"; continue; }
    python3 - "$out/r.json" "$round" "$name" "$(sha256sum < "$film" | cut -c1-16)" >> "$tsv" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
def find(o, key):
    if isinstance(o, dict):
        if key in o: return o[key]
        for v in o.values():
            f = find(v, key)
            if f is not None: return f
    return None
bvh = find(r, "bvh") or {}
layout = bvh.get("layout", "?") if isinstance(bvh, dict) else "?"
occ = find(r, "pixel_occupancy") or {}
print(f"{sys.argv[2]}\t{sys.argv[3]}\t{r['device_seconds'] * 1e3}\t{sys.argv[4]}\t{layout}\t{occ.get('min_blocks_per_sm', '-')}")
PY
  done < "$cases"
done
python3 - "$tsv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
print(f"{'case':28s} {'median ms':>10s}  layout  blocks  films  (rounds)")
for n in dict.fromkeys(r["case"] for r in rows):
    rs = [r for r in rows if r["case"] == n]
    ms = [float(r["device_ms"]) for r in rs]
    films = sorted({r["film_sha"] for r in rs})
    print(f"{n:28s} {statistics.median(ms):10.3f}  {rs[0]['layout']:6s}  {rs[0]['blocks']:>6s}  {','.join(films)}  "
          f"({', '.join(f'{x:.2f}' for x in ms)})")
PY
