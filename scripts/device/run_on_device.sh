#!/usr/bin/env bash
# Builds, tests, sanitizes and benchmarks the GPU tracer on a GPU host (the device
# machine), writing everything under $OUT (default: ./device-out). Phases are chosen
# by arguments: build test sanitize bench ico accuracy layouts (default: all but layouts).
#   layouts: the GPU BVH layouts (PATHBENCH_GPU_BVH: binary, wide4, wide8, brute, leaves)
#   side by side, interleaved: paper-cornell, ico:0-2 and ico:8 renders, raw ray casts
#   (pathbench-bench --preset gpu-layouts), and the GPU tests in each layout.
#   source .gpu-deps/unpack.sh is done here; see ../shared/gpu-host/README.md.
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
OUT=${OUT:-$PWD/device-out}
mkdir -p "$OUT/logs" "$OUT/json"
pack() {
  tar czf "$OUT/device-results.tar.gz" -C "$OUT" logs json summary.txt $(cd "$OUT" && ls -d accuracy 2>/dev/null) 2>/dev/null
  rm -rf "$OUT/logs" "$OUT/json" "$OUT/accuracy"
}
trap pack EXIT
phases=${*:-build test sanitize bench ico accuracy}  # layouts: only when asked for
has() { [[ " $phases " == *" $1 "* ]]; }
log() { echo "== $(date -u +%H:%M:%S) $*" | tee -a "$OUT/summary.txt"; }
B=build-gpu
PB=$B/bin/pathbench

# The commit this tree is a copy of, for the reports (a .git in the copy, if any, is stale;
# cmake/git_revision.cmake lets this name win).
if [ -f .gpu-deps/source-commit ]; then export PATHBENCH_SOURCE_COMMIT=$(cat .gpu-deps/source-commit); fi
log "source commit: ${PATHBENCH_SOURCE_COMMIT:-unknown}"
if [ -f .gpu-deps/unpack.sh ]; then source .gpu-deps/unpack.sh >/dev/null; fi
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.sm,clocks.max.sm --format=csv | tee "$OUT/logs/nvidia-smi.txt"

if has build; then
  log "configure + build"
  cmake -S . -B $B -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
        -DCMAKE_CUDA_ARCHITECTURES=90 -DPATHBENCH_CUDA_RESOURCE_REPORT=ON > "$OUT/logs/configure.txt" 2>&1 \
    || { tail -30 "$OUT/logs/configure.txt"; exit 1; }
  cmake --build $B -j 16 --target pathbench pathbench_gpu_tests pathbench_traversal_tests > "$OUT/logs/build.txt" 2>&1 \
    || { grep -E "error|FAILED" -A3 "$OUT/logs/build.txt" | head -60; exit 1; }
  cmake --build $B -j 16 > "$OUT/logs/build-all.txt" 2>&1 || log "warning: building everything else failed (see build-all.txt)"
  grep -E "Compiling entry|stack frame|registers" "$OUT/logs/build.txt" > "$OUT/logs/ptxas.txt" || true
  log "build ok"
fi

if has test; then
  log "ctest -L gpu"
  (cd $B && ctest -L gpu --output-on-failure -V --timeout 300) > "$OUT/logs/ctest-gpu.txt" 2>&1
  log "ctest -L gpu rc=$?: $(grep -E 'tests passed|tests failed' $OUT/logs/ctest-gpu.txt)"
  grep -E "INFO|FAILED|Failure" "$OUT/logs/ctest-gpu.txt" | sed 's/^[0-9]*: //' | sort -u | tee -a "$OUT/summary.txt"
  log "stability suite on the GPU (gpu.* tests)"
  grep -E "^ *[0-9]+/[0-9]+ Test +#[0-9]+: gpu\." "$OUT/logs/ctest-gpu.txt" | sed 's/^ *[0-9]*\/[0-9]* //' > "$OUT/logs/stability-gpu.txt"
  echo "$(grep -c Passed "$OUT/logs/stability-gpu.txt") passed, $(grep -vc Passed "$OUT/logs/stability-gpu.txt") not passed" | tee -a "$OUT/summary.txt"
  log "ctest -L unit"
  (cd $B && ctest -L unit --output-on-failure -j 16 --timeout 600) > "$OUT/logs/ctest-unit.txt" 2>&1
  log "ctest -L unit rc=$?: $(grep -E 'tests passed|tests failed' $OUT/logs/ctest-unit.txt)"
fi

render() {  # name, then pathbench render arguments
  local name=$1; shift
  timeout 120 $PB render --device gpu --quiet --report "$OUT/json/$name.json" "$@" > "$OUT/logs/$name.txt" 2>&1
  local rc=$?
  python3 - "$OUT/json/$name.json" "$name" "$rc" <<'PY' | tee -a "$OUT/summary.txt"
import json, sys
path, name, rc = sys.argv[1], sys.argv[2], sys.argv[3]
try:
    j = json.load(open(path))
except Exception:
    print(f"{name}: rc={rc} (no report)"); sys.exit()
bvh = j.get('bvh', {})
print(f"{name}: rc={rc} bvh {bvh.get('layout', '?')} device {j['device_seconds']*1e3:.2f} ms, wall {j['seconds']*1e3:.1f} ms, "
      f"{j['rays']['total']/j['device_seconds']/1e9:.2f} Grays/s, peak device {j['peak_device_bytes']/1e6:.1f} MB "
      f"(alloc {j.get('device_bytes_allocated_peak',0)/1e6:.1f}, meminfo {j.get('device_bytes_meminfo_delta_peak',0)/1e6:.1f}), "
      f"state {j['state_bytes_per_path']} B/path, pif {j['paths_in_flight']}, discarded {j['discarded_samples']}")
PY
}
paper="--scene paper-cornell --width 256 --height 256 --spp 800 --bounces 2 --sampling nee"
# sanitizer_run LOG TOOL PATHBENCH ARGS: one compute-sanitizer run, its status and summary line.
# shellcheck source=scripts/device/sanitizer_run.sh
source scripts/device/sanitizer_run.sh

if has sanitize; then
  small="--scene paper-cornell --width 32 --height 32 --spp 4 --bounces 2 --sampling nee --device gpu --quiet"
  for tool in memcheck racecheck; do
    for st in pixel wavefront paper-queue; do
      log "compute-sanitizer $tool $st"
      sanitizer_run "$OUT/logs/sanitizer-$tool-$st.txt" $tool $PB $small --strategy $st --paths-in-flight 1000 | tee -a "$OUT/summary.txt"
    done
  done
  # The pixel megakernel's lanes ordered by the first bounce (sample_order.cuh: a counting sort
  # in shared memory): the binary BVH at 8 blocks, 300 spp (units of 256 and of 44).
  ordered="--scene paper-cornell-ico:2 --width 8 --height 8 --spp 300 --bounces 2 --sampling nee --device gpu --quiet"
  for tool in memcheck racecheck; do
    log "compute-sanitizer $tool pixel, lanes ordered"
    PATHBENCH_GPU_BVH=binary PATHBENCH_GPU_PIXEL_BLOCKS=8 sanitizer_run "$OUT/logs/sanitizer-$tool-pixel-ordered.txt" $tool $PB $ordered --strategy pixel \
      | tee -a "$OUT/summary.txt"
  done
  # Whole warps of one pixel (spp a multiple of 32: the film add by REDUX, device_film.cuh).
  for st in pixel wavefront; do
    log "compute-sanitizer memcheck $st, 64 spp"
    sanitizer_run "$OUT/logs/sanitizer-memcheck-spp64-$st.txt" memcheck $PB ${small/--spp 4/--spp 64} --strategy $st --paths-in-flight 1000 \
      | tee -a "$OUT/summary.txt"
  done
fi

if has bench; then
  log "paper-cornell 256x256x800, 2 bounces, nee"
  for i in 1 2 3 4 5; do render paper-pixel-$i $paper --strategy pixel; done
  for i in 1 2 3; do render paper-wavefront-$i $paper --strategy wavefront; done
  for pif in 135168 270336 675840 2703360; do render paper-wavefront-pif$pif $paper --strategy wavefront --paths-in-flight $pif; done
  render paper-paperqueue $paper --strategy paper-queue
  log "profiles"
  timeout 60 $PB render --device gpu --quiet $paper --strategy pixel --profile | tee -a "$OUT/summary.txt"
  timeout 60 $PB render --device gpu --quiet $paper --strategy wavefront --profile | tee -a "$OUT/summary.txt"
  timeout 60 $PB render --device gpu --quiet $paper --strategy paper-queue --profile | tee -a "$OUT/summary.txt"
  log "2048x2048x1024"
  big="--scene paper-cornell --width 2048 --height 2048 --spp 1024 --bounces 2 --sampling nee"
  render big-wavefront $big --strategy wavefront
  render big-pixel $big --strategy pixel
  timeout 60 $PB render --device gpu --quiet $big --strategy paper-queue > "$OUT/logs/big-paperqueue-refusal.txt" 2>&1
  echo "paper-queue 2048x2048x1024: rc=$? $(cat $OUT/logs/big-paperqueue-refusal.txt)" | tee -a "$OUT/summary.txt"
fi

if has ico; then
  log "paper-cornell-ico:8 256x256x800, 2 bounces, nee"
  ico="--scene paper-cornell-ico:8 --width 256 --height 256 --spp 800 --bounces 2 --sampling nee"
  for i in 1 2 3; do render ico-pixel-$i $ico --strategy pixel; done
  render ico-wavefront $ico --strategy wavefront
  timeout 60 $PB render --device gpu --quiet $ico --strategy pixel --profile | tee -a "$OUT/summary.txt"
fi

# Seconds since the script began: the layouts phase leaves out its last, optional
# pieces (sanitizers, per-layout ctest) past LAYOUTS_BUDGET_S, so that the results are
# packed before a device call's time limit.
in_budget() { [ "$SECONDS" -lt "${LAYOUTS_BUDGET_S:-500}" ] || { log "skipped (past ${LAYOUTS_BUDGET_S:-500} s): $*"; return 1; }; }

if has layouts; then
  layouts=${LAYOUTS:-binary wide4 wide8 brute leaves}
  big_layouts=$(for l in $layouts; do [[ $l == brute || $l == leaves ]] || echo -n "$l "; done)  # for ico:8
  ico="--scene paper-cornell-ico:8 --width 256 --height 256 --spp 800 --bounces 2 --sampling nee"
  log "GPU BVH layouts: paper-cornell 256x256x800 nee, rounds interleaved ($layouts)"
  for round in 1 2 3; do
    for l in $layouts; do export PATHBENCH_GPU_BVH=$l; render layout-paper-pixel-$l-$round $paper --strategy pixel; done
  done
  for round in 1 2; do
    for l in $layouts; do export PATHBENCH_GPU_BVH=$l; render layout-paper-wavefront-$l-$round $paper --strategy wavefront; done
  done
  log "GPU BVH layouts: small scenes (paper-cornell-ico:0..2, 256x256x800 nee pixel), where the tiny-scene layouts end"
  for round in 1 2; do
    for n in 0 1 2; do
      for l in $layouts; do
        export PATHBENCH_GPU_BVH=$l
        render layout-ico$n-pixel-$l-$round ${paper/paper-cornell/paper-cornell-ico:$n} --strategy pixel
      done
    done
  done
  log "GPU BVH layouts: paper-cornell-ico:8 (brute force and leaves left out: 1.31 M triangles)"
  for round in 1 2; do
    for l in $big_layouts; do export PATHBENCH_GPU_BVH=$l; render layout-ico-pixel-$l-$round $ico --strategy pixel; done
  done
  for l in $big_layouts; do export PATHBENCH_GPU_BVH=$l; render layout-ico-wavefront-$l $ico --strategy wavefront; done
  for l in $layouts; do
    export PATHBENCH_GPU_BVH=$l
    timeout 60 $PB render --device gpu --quiet $paper --strategy pixel --profile > "$OUT/logs/layout-profile-$l.txt" 2>&1
  done
  unset PATHBENCH_GPU_BVH
  log "render medians per layout (device ms)"
  python3 - "$OUT/json" <<'PY' | tee -a "$OUT/summary.txt"
import glob, json, os, re, statistics, sys
runs = {}
for f in glob.glob(os.path.join(sys.argv[1], "layout-*.json")):
    m = re.match(r"layout-(paper|ico\d?)-(pixel|wavefront)-(\w+?)(?:-\d+)?\.json$", os.path.basename(f))
    if not m:
        continue
    try:
        j = json.load(open(f))
    except Exception:
        continue
    runs.setdefault(m.groups(), []).append(j["device_seconds"] * 1e3)
for key in sorted(runs):
    v = runs[key]
    print(f"{key[0]:6s} {key[1]:10s} {key[2]:7s} median {statistics.median(v):8.2f} ms  (n={len(v)}: {', '.join(f'{x:.2f}' for x in v)})")
PY
  log "raw ray casts per layout (pathbench-bench --preset gpu-layouts)"
  timeout 300 $B/bin/pathbench-bench --preset gpu-layouts --benchmark_out="$OUT/json/bench-gpu-layouts.json" \
    --benchmark_out_format=json > "$OUT/logs/bench-gpu-layouts.txt" 2>&1
  log "bench rc=$?"
  python3 - "$OUT/json/bench-gpu-layouts.json" <<'PY' | tee -a "$OUT/summary.txt"
import json, sys
try:
    rows = json.load(open(sys.argv[1]))["benchmarks"]
except Exception as e:
    print(f"no bench JSON: {e}"); sys.exit()
for r in rows:
    if "rays_per_second" in r:
        print(f"{r['name']:64s} {r['rays_per_second']/1e9:7.2f} Grays/s")
    else:
        print(f"{r['name']:64s} {r.get('error_message', 'no rate')}")
PY
  log "GPU tests in each layout (ctest -L gpu)"
  for l in ${CTEST_LAYOUTS:-leaves wide8 brute binary wide4}; do
    in_budget "ctest -L gpu in layout $l" || continue
    export PATHBENCH_GPU_BVH=$l
    (cd $B && ctest -L gpu --output-on-failure -V --timeout 300) > "$OUT/logs/ctest-gpu-$l.txt" 2>&1
    log "ctest -L gpu, PATHBENCH_GPU_BVH=$l rc=$?: $(grep -E 'tests passed|tests failed' $OUT/logs/ctest-gpu-$l.txt)"
    grep -E "FAILED|Failure" "$OUT/logs/ctest-gpu-$l.txt" | sed 's/^[0-9]*: //' | sort -u | head -20 | tee -a "$OUT/summary.txt"
  done
  unset PATHBENCH_GPU_BVH
  log "compute-sanitizer in each layout (paper-cornell-ico:2, 32x32x4)"
  small_ico="--scene paper-cornell-ico:2 --width 32 --height 32 --spp 4 --bounces 2 --sampling nee --device gpu --quiet"
  for l in $layouts; do
    in_budget "sanitizers in layout $l" || continue
    export PATHBENCH_GPU_BVH=$l
    for tool in memcheck racecheck; do
      for st in pixel wavefront; do
        echo "$l $tool $st: $(sanitizer_run "$OUT/logs/sanitizer-$tool-$st-$l.txt" $tool $PB $small_ico --strategy $st --paths-in-flight 1000)" \
          | tee -a "$OUT/summary.txt"
      done
    done
  done
  unset PATHBENCH_GPU_BVH
fi

if has accuracy; then
  # The speed/accuracy sweep on the GPU (pixel strategy: it alone runs every variant).
  # No Python packages here: FLIP, plots and table are made back home from these files
  # (tools/accuracy_report.py).
  for scene in ${ACCURACY_SCENES:-paper-cornell cornell-box}; do
    log "accuracy $scene"
    timeout ${ACCURACY_TIMEOUT:-240} $PB accuracy --scene $scene --device gpu --reference-spp 131072 --max-spp 16384 --max-seconds 10 \
      --no-report-tool --out-dir "$OUT/accuracy/$scene" > "$OUT/logs/accuracy-$scene.txt" 2>&1
    log "accuracy $scene rc=$?"
  done
fi

log "done"
