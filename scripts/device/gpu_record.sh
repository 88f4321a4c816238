#!/usr/bin/env bash
# The GPU call of record, on the GPU host (one device call, under 10 minutes on an H100):
# build, tests and sanitizers of this tree (scripts/device/run_on_device.sh), the committed bench JSON
# (bench-paper-gpu.json, bench-raycast-gpu.json), paper-cornell-ico:8 and 2048x2048x1024
# renders, an interleaved A/B (scripts/device/gpu_ab.sh: renders and raw casts) against a base made by reversing
# BASE_PATCH on a copy of this tree, and the roofline (scripts/device/gpu_roofline.sh) if time is
# left. Everything goes to OUT_DIR; console output says what passed.
#   scripts/device/gpu_record.sh OUT_DIR BASE_PATCH [CASES_FILE]
# BASE_PATCH: `git diff BASE -- gpu/ bvh/ common/` made on the development host, or a whole base
# tree `git archive BASE | xz > base.tar.xz` (where the change moved files), or `none`: no base
# build and no A/B; CASES_FILE: the A/B's cases (scripts/device/gpu_ab.sh's format), else its defaults. Needs .gpu-deps (see
# ../shared/gpu-host/README.md); PATHBENCH_SOURCE_COMMIT names the commit in the reports
# (from .gpu-deps/source-commit when set there).
set -uo pipefail
out=${1:?usage: scripts/device/gpu_record.sh OUT_DIR BASE_PATCH [CASES_FILE]}
patch_file=${2:?usage: scripts/device/gpu_record.sh OUT_DIR BASE_PATCH [CASES_FILE]}
[ "$patch_file" = none ] || patch_file=$(realpath "$patch_file")
cases=${3:+$(realpath "$3")}
for f in ${patch_file/#none/} ${cases:+"$cases"}; do  # before anything is made
  if [ ! -f "$f" ] || [ ! -r "$f" ]; then echo "gpu_record.sh: $f: not a readable file" >&2; exit 2; fi
done
mkdir -p "$out"
out=$(realpath "$out")
cd "$(dirname "${BASH_SOURCE[0]}")/../.." || exit 1
# shellcheck disable=SC1091  # made on the development host (../shared/gpu-host/README.md)
if [ -f .gpu-deps/unpack.sh ]; then source .gpu-deps/unpack.sh > /dev/null; fi
export PATH=$PATH:/usr/local/cuda/bin
if [ -f .gpu-deps/source-commit ]; then
  PATHBENCH_SOURCE_COMMIT=$(cat .gpu-deps/source-commit)
  export PATHBENCH_SOURCE_COMMIT
fi
echo "source commit ${PATHBENCH_SOURCE_COMMIT:-unknown}"
nvidia-smi --query-gpu=name,driver_version,temperature.gpu,clocks.sm,clocks.max.sm,clocks_event_reasons.active \
  --format=csv > "$out/gpu-state-start.csv" 2>&1
base=/tmp/pathbench-base
rm -rf $base && mkdir -p $base
if [ "$patch_file" = none ]; then
  echo "no base: no A/B"
elif [[ $patch_file == *.tar.xz ]]; then  # a whole base tree (`git archive BASE | xz`): where files moved
  tar -xJf "$patch_file" -C $base || { echo "the base tree $patch_file does not unpack"; exit 1; }
else
  tar --exclude=./build-gpu --exclude=./build --exclude=./.git -cf - . | tar -xf - -C $base
  (cd $base && patch -s -R -p1 < "$patch_file") || { echo "the base patch does not reverse on this tree"; exit 1; }
fi
[ "$patch_file" = none ] || (cmake -S $base -B $base/build-gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
   -DCMAKE_CUDA_ARCHITECTURES=90 > /dev/null 2>&1 && cmake --build $base/build-gpu -j 5 --target pathbench pathbench-bench \
   > "$out/base-build.log" 2>&1; echo "base build rc=$?") &
OUT=$out bash scripts/device/run_on_device.sh build test sanitize > "$out/run_on_device.txt" 2>&1
echo "build + test + sanitize rc=$?"
wait
grep -E "ctest|passed|ERROR SUMMARY|hazard|PaperFrameWithinAcceptance" "$out/summary.txt" | head -24
PB=build-gpu/bin/pathbench
for what in paper raycast; do
  filter=render/gpu; [ $what = raycast ] && filter=raycast/gpu
  timeout 200 build-gpu/bin/pathbench-bench --preset paper --benchmark_filter=$filter --benchmark_repetitions=5 \
    --benchmark_out="$out/bench-$what-gpu.json" --benchmark_out_format=json > "$out/bench-$what-gpu.txt" 2>&1
  echo "bench $what rc=$?"
done
mkdir -p "$out/renders"
ico=(--scene paper-cornell-ico:8 --width 256 --height 256 --spp 800 --bounces 2 --sampling nee)
for i in 1 2 3; do timeout 100 $PB render --device gpu --quiet "${ico[@]}" --strategy pixel --report "$out/renders/ico8-pixel-$i.json" > /dev/null 2>&1; done
timeout 100 $PB render --device gpu --quiet "${ico[@]}" --strategy wavefront --report "$out/renders/ico8-wavefront.json" > /dev/null 2>&1
big=(--scene paper-cornell --width 2048 --height 2048 --spp 1024 --bounces 2 --sampling nee)
timeout 100 $PB render --device gpu --quiet "${big[@]}" --strategy wavefront --report "$out/renders/big-wavefront.json" > /dev/null 2>&1
python3 - "$out" <<'PY'
import glob, json, os, sys
out = sys.argv[1]
for f in sorted(glob.glob(os.path.join(out, "renders", "*.json"))):
    j = json.load(open(f))
    print(f"{os.path.basename(f)}: {j['device_seconds']*1e3:.2f} ms, peak device {j['peak_device_bytes']/1e6:.1f} MB")
for name in ["bench-paper-gpu.json", "bench-raycast-gpu.json"]:
    try:
        bs = json.load(open(os.path.join(out, name)))["benchmarks"]
    except Exception as e:
        print(name, "missing:", e)
        continue
    for b in bs:
        if b.get("aggregate_name") == "median":
            extra = f" {b['rays_per_second']/1e9:.2f} Grays/s" if "rays_per_second" in b else ""
            print(f"{b['run_name'][:70]:70s} {b['real_time']:.3f} {b['time_unit']}{extra}")
PY
if [ "$patch_file" != none ]; then
  NO_RAYCAST=${NO_RAYCAST:-} CASES=$cases bash scripts/device/gpu_ab.sh $base/build-gpu build-gpu "$out/ab" 3 > "$out/ab-summary.txt" 2>&1
  echo "ab rc=$?"; cat "$out/ab-summary.txt"
  rm -rf "$out/ab/films"
fi
# The roofline took 30 s on an H100 at 90a862f; ROOFLINE_BEFORE_S: start it only before this.
if [ $SECONDS -lt "${ROOFLINE_BEFORE_S:-480}" ]; then
  LAUNCHES=60 bash scripts/device/gpu_roofline.sh build-gpu "$out/roofline" > "$out/roofline.txt" 2>&1
  echo "roofline rc=$? at ${SECONDS}s"
else
  echo "roofline skipped at ${SECONDS}s"
fi
nvidia-smi --query-gpu=name,temperature.gpu,clocks.sm,clocks_event_reasons.active --format=csv > "$out/gpu-state-end.csv" 2>&1
