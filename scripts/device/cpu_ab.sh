#!/usr/bin/env bash
# Interleaved A/B of two builds of the CPU tracer on one host (e.g. the GPU host's Xeon):
# for each round, every case is rendered by build A and then by build B (one process each,
# all threads, the report's wall seconds of the render), and each film's hash is kept.
# Prints, per case, the median seconds of A and B, B/A, and whether the films of each
# build agree across rounds (and with the other build's).
#   scripts/device/cpu_ab.sh BUILD_A BUILD_B OUT_DIR [ROUNDS]
# Cases: the paper's frame (paper-cornell 256x256x800, 2 bounces, nee), pixel and
# wavefront, with the best ISA the CPU has and with --isa avx2. CASES as gpu_ab.sh's.
set -uo pipefail
a=${1:?usage: scripts/device/cpu_ab.sh BUILD_A BUILD_B OUT_DIR [ROUNDS]}
b=${2:?usage: scripts/device/cpu_ab.sh BUILD_A BUILD_B OUT_DIR [ROUNDS]}
out=${3:?usage: scripts/device/cpu_ab.sh BUILD_A BUILD_B OUT_DIR [ROUNDS]}
rounds=${4:-5}
mkdir -p "$out/films"
frame="--scene paper-cornell --width 256 --height 256 --spp 800 --bounces 2 --sampling nee"
default_cases="paper-pixel | $frame --strategy pixel
paper-wavefront | $frame --strategy wavefront
paper-pixel-avx2 | $frame --strategy pixel --isa avx2
paper-wavefront-avx2 | $frame --strategy wavefront --isa avx2"
cases=$(if [ -n "${CASES:-}" ]; then cat "$CASES"; else echo "$default_cases"; fi)
tsv="$out/cpu-ab.tsv"
echo -e "round\tcase\tbuild\tseconds\tfilm_sha\tload1" > "$tsv"
for round in $(seq 1 "$rounds"); do
  while IFS='|' read -r name opts; do
    name=${name//[[:space:]]/}
    for side in A B; do
      dir=$a; [ $side = B ] && dir=$b
      film="$out/films/$name-$side.pfm"
      # shellcheck disable=SC2086
      timeout 120 "$dir/bin/pathbench" render --device cpu --quiet $opts --out "$film" --report "$out/r.json" \
        > "$out/last.log" 2>&1 || { echo "$name $side failed: $(tail -2 "$out/last.log")"; continue; }
      s=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['seconds'])" "$out/r.json")
      echo -e "$round\t$name\t$side\t$s\t$(sha256sum < "$film" | cut -c1-16)\t$(cut -d' ' -f1 /proc/loadavg)" >> "$tsv"
    done
  done <<< "$cases"
done
python3 - "$tsv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
print(f"{'case':24s} {'A s':>8s} {'B s':>8s} {'B/A':>6s}  films")
for n in dict.fromkeys(r["case"] for r in rows):
    t = {s: [float(r["seconds"]) for r in rows if r["case"] == n and r["build"] == s] for s in "AB"}
    h = {s: {r["film_sha"] for r in rows if r["case"] == n and r["build"] == s} for s in "AB"}
    if not t["A"] or not t["B"]:
        print(f"{n:24s} missing"); continue
    ma, mb = statistics.median(t["A"]), statistics.median(t["B"])
    films = ("A = B" if h["A"] == h["B"] else "A != B") + f" (A {len(h['A'])} hash(es), B {len(h['B'])})"
    print(f"{n:24s} {ma:8.3f} {mb:8.3f} {mb/ma:6.3f}  {films}  (A {', '.join(f'{x:.3f}' for x in t['A'])}; "
          f"B {', '.join(f'{x:.3f}' for x in t['B'])})")
PY
