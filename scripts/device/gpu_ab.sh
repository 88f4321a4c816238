#!/usr/bin/env bash
# Interleaved A/B of two builds of the GPU tracer on one GPU host: for each round, every
# case is rendered by build A and then by build B (one process each, CUDA-event device
# time after the warm-up frame), and each film's hash is kept; then the raw ray-cast rows
# of pathbench-bench for both. Prints, per case, the median device ms of A and B, B/A,
# and whether every film of B hashed as A's (a change meant to keep the images).
# NO_RAYCAST=1 leaves out the ray-cast rows.
#   scripts/device/gpu_ab.sh BUILD_A BUILD_B OUT_DIR [ROUNDS]
# Cases: CASES (a file of "name | [VAR=value ...] pathbench render options" lines: leading
# VAR=value words are set in the environment of both builds' runs), else the paper's
# frame on paper-cornell (pixel, wavefront, paper-queue; nee and uniform) and
# paper-cornell-ico:8 (pixel).
set -uo pipefail
a=${1:?usage: scripts/device/gpu_ab.sh BUILD_A BUILD_B OUT_DIR [ROUNDS]}
b=${2:?usage: scripts/device/gpu_ab.sh BUILD_A BUILD_B OUT_DIR [ROUNDS]}
out=${3:?usage: scripts/device/gpu_ab.sh BUILD_A BUILD_B OUT_DIR [ROUNDS]}
rounds=${4:-5}
mkdir -p "$out/films"
frame="--width 256 --height 256 --spp 800 --bounces 2"
default_cases="paper-pixel-nee | --scene paper-cornell $frame --sampling nee --strategy pixel
paper-wavefront-nee | --scene paper-cornell $frame --sampling nee --strategy wavefront
paper-queue-nee | --scene paper-cornell $frame --sampling nee --strategy paper-queue
paper-pixel-uniform | --scene paper-cornell $frame --sampling uniform --strategy pixel
ico8-pixel-nee | --scene paper-cornell-ico:8 $frame --sampling nee --strategy pixel"
cases=$(if [ -n "${CASES:-}" ]; then cat "$CASES"; else echo "$default_cases"; fi)
tsv="$out/ab.tsv"
echo -e "round\tcase\tbuild\tdevice_ms\tfilm_sha" > "$tsv"
nvidia-smi --query-gpu=name,driver_version,temperature.gpu,clocks.sm,clocks.max.sm,clocks_throttle_reasons.active \
  --format=csv > "$out/gpu-state-before.csv" 2>&1
for round in $(seq 1 "$rounds"); do
  while IFS='|' read -r name opts; do
    name=${name//[[:space:]]/}  # names have no spaces: trim the padding around "|"
    opts_env="" opts_args=""
    for w in $opts; do
      if [ -z "$opts_args" ] && [[ $w =~ ^[A-Z_][A-Z0-9_]*= ]]; then opts_env+=" $w"; else opts_args+=" $w"; fi
    done
    for side in A B; do
      dir=$a; [ $side = B ] && dir=$b
      film="$out/films/$name-$side.pfm"
      # shellcheck disable=SC2086
      timeout 300 env $opts_env "$dir/bin/pathbench" render --device gpu --quiet $opts_args --out "$film" --report "$out/r.json" \
        > "$out/last.log" 2>&1 || { echo "$name $side failed: $(tail -2 "$out/last.log")"; continue; }
      ms=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['device_seconds']*1e3)" "$out/r.json")
      echo -e "$round\t$name\t$side\t$ms\t$(sha256sum < "$film" | cut -c1-16)" >> "$tsv"
    done
  done <<< "$cases"
done
nvidia-smi --query-gpu=name,temperature.gpu,clocks.sm,clocks_throttle_reasons.active --format=csv \
  > "$out/gpu-state-after.csv" 2>&1
for side in A B; do
  [ -n "${NO_RAYCAST:-}" ] && break  # NO_RAYCAST=1: renders only
  dir=$a; [ $side = B ] && dir=$b
  timeout 300 "$dir/bin/pathbench-bench" --preset paper --benchmark_filter='^raycast/gpu/' --benchmark_repetitions=3 \
    --benchmark_out="$out/raycast-$side.json" --benchmark_out_format=json > "$out/raycast-$side.log" 2>&1
  echo "raycast $side rc=$?"
done
python3 - "$out" <<'PY'
import csv, json, statistics, sys, os
out = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(out, "ab.tsv")), delimiter="\t"))
names = list(dict.fromkeys(r["case"] for r in rows))
print(f"{'case':24s} {'A ms':>9s} {'B ms':>9s} {'B/A':>6s}  films")
for n in names:
    t = {s: [float(r["device_ms"]) for r in rows if r["case"] == n and r["build"] == s] for s in "AB"}
    h = {s: {r["film_sha"] for r in rows if r["case"] == n and r["build"] == s} for s in "AB"}
    if not t["A"] or not t["B"]:
        print(f"{n:24s} missing"); continue
    ma, mb = statistics.median(t["A"]), statistics.median(t["B"])
    same = "same" if h["A"] == h["B"] and len(h["A"]) == 1 else f"DIFFER A={sorted(h['A'])} B={sorted(h['B'])}"
    print(f"{n:24s} {ma:9.3f} {mb:9.3f} {mb/ma:6.3f}  {same}  (A {', '.join(f'{x:.2f}' for x in t['A'])}; B {', '.join(f'{x:.2f}' for x in t['B'])})")
for s in "AB":
    try:
        bench = json.load(open(os.path.join(out, f"raycast-{s}.json")))["benchmarks"]
    except Exception as e:
        print(f"raycast {s}: no JSON ({e})"); continue
    for r in bench:
        if r.get("aggregate_name") == "median" and "rays_per_second" in r:
            print(f"raycast {s} {r['run_name']:52s} {r['rays_per_second']/1e9:7.2f} Grays/s")
PY
