#!/usr/bin/env bash
# Interleaved comparison of several (build, environment) variants of the GPU tracer on one
# GPU host, where gpu_ab.sh compares two builds under one environment: for each case and
# round, every variant renders in turn (one process each, CUDA-event device time after the
# warm-up frame) and its film's hash is kept. Prints per case the median device ms of each
# variant, its ratio to the first variant, and the films' hashes (one per variant when a
# change keeps the images).
#   scripts/device/gpu_variants_ab.sh VARIANTS CASES OUT_DIR
# VARIANTS: a file of "name | build_dir [VAR=value ...]" lines (the build's bin/pathbench, run
# with those variables set); a case's line may name the variants it runs: CASES: a file of
# "name | rounds | variant,variant,... or * | pathbench render options" lines.
set -uo pipefail
variants=${1:?usage: scripts/device/gpu_variants_ab.sh VARIANTS CASES OUT_DIR}
cases=${2:?usage: scripts/device/gpu_variants_ab.sh VARIANTS CASES OUT_DIR}
out=${3:?usage: scripts/device/gpu_variants_ab.sh VARIANTS CASES OUT_DIR}
mkdir -p "$out/films"
tsv="$out/variants.tsv"
echo -e "case\tround\tvariant\tdevice_ms\tfilm_sha\tblocks\tparked\tordered\tbvh" > "$tsv"
trim() { local s=$1; s=${s#"${s%%[![:space:]]*}"}; echo "${s%"${s##*[![:space:]]}"}"; }
while IFS='|' read -r cname rounds which opts; do
  cname=$(trim "$cname"); rounds=$(trim "$rounds"); which=$(trim "$which")
  [ -z "$cname" ] && continue
  for round in $(seq 1 "$rounds"); do
    while IFS='|' read -r vname spec; do
      vname=$(trim "$vname")
      [ -z "$vname" ] && continue
      [ "$which" != "*" ] && [[ ",$which," != *",$vname,"* ]] && continue
      read -r dir venv <<< "$spec"
      film="$out/films/$cname-$vname.pfm"
      # shellcheck disable=SC2086
      timeout 300 env $venv "$dir/bin/pathbench" render --device gpu --quiet $opts --out "$film" --report "$out/r.json" < /dev/null \
        > "$out/last.log" 2>&1 || { echo "$cname $vname failed: $(tail -2 "$out/last.log")"; continue; }
      python3 - "$out/r.json" "$cname" "$round" "$vname" "$(sha256sum < "$film" | cut -c1-16)" >> "$tsv" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
occ = r.get("pixel_occupancy") or {}
print("\t".join([sys.argv[2], sys.argv[3], sys.argv[4], f"{r['device_seconds'] * 1e3:.4f}", sys.argv[5],
                 str(occ.get("min_blocks_per_sm", "")), str(occ.get("parked_path_state", "")),
                 str(occ.get("lanes_ordered_by_first_bounce", "")),
                 "{layout} {nodes} nodes {triangle_refs} refs depth {depth} SAH {sah_cost:.2f} {build_seconds:.2f} s".format(
                     **{"layout": "?", "nodes": 0, "triangle_refs": 0, "depth": 0, "sah_cost": 0.0, "build_seconds": 0.0,
                        **r.get("bvh", {})})]))
PY
    done < "$variants"
  done
done < "$cases"
python3 - "$tsv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
for case in dict.fromkeys(r["case"] for r in rows):
    mine = [r for r in rows if r["case"] == case]
    first = None
    for v in dict.fromkeys(r["variant"] for r in mine):
        ms = [float(r["device_ms"]) for r in mine if r["variant"] == v]
        films = sorted({r["film_sha"] for r in mine if r["variant"] == v})
        occ = {(r["blocks"], r["parked"], r["ordered"]) for r in mine if r["variant"] == v}
        med = statistics.median(ms)
        first = first or med
        bvh = sorted({r["bvh"] for r in mine if r["variant"] == v})
        print(f"{case:22s} {v:18s} {med:9.3f} ms  {med / first:6.3f}  films {','.join(films)}  occ {sorted(occ)}  "
              f"({', '.join(f'{x:.2f}' for x in ms)})  bvh {'; '.join(bvh)}")
PY
