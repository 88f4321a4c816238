#!/usr/bin/env bash
# MPI ranks on a GPU host (issues 13, 30, 31), for the device machine: build with MPI (and
# NCCL where found: PATHBENCH_NCCL=ON to insist), run the mpi tests, check that 2 GPU ranks (on one GPU when only one is visible) and the
# CPU+GPU hybrid give the one-GPU image byte for byte, that pathbench-bench's GPU render
# benchmarks over 2 ranks give one process's film hashes, and run tools/mpi_scaling.py.
# Everything lands under $OUT (default ./device-out). Phases: build gpu check bench reduce scaling
# hybrid cache bands repeat largemesh (gpu: ctest -L gpu in the same build, GPU_TESTS=regex for a
# subset; hybrid: one GPU alone against the hybrid, interleaved rounds, REPS=5 by default;
# scaling: tools/mpi_scaling.py --gpus <all visible>, SCALING_REPS=3, CPU_RANKS=1,2,4,
# HYBRID_ROUNDS (REPS), RECORD=1 records it into the history (--commit $PATHBENCH_SOURCE_COMMIT);
# cache: the hybrid with and without gpu::render's kept setup (PATHBENCH_GPU_RENDER_CACHE=0)
# against one GPU, interleaved, CACHE_REPS=5; bands: 2 GPU ranks reducing at the end against band
# by band (PATHBENCH_REDUCE_BANDS), BANDS_REPS=3; repeat: CPU ranks' images against one
# process's, REPEAT_RUNS=8 times each (the NOT IDENTICAL hunt); largemesh: the suite's large
# mesh on one GPU and over the GPU ranks, PATHBENCH_DATA_DIR holding its mesh; hunt: issue 30's
# film difference, HUNT_RUNS=30 runs of 3 CPU ranks at 256x256x800 (static: 272 + 272 + 256
# samples a pixel) with each rank's film hash and Embree layout, against one process, and
# HUNT_ICO_RUNS=3 of paper-cornell-ico:3 (above the tiny-scene limit: Embree's packets) at
# 3 ranks, static and dynamic, against one process; hunt/ keeps a line per run). TARGETS: what
# to build. PB=path: a pathbench built elsewhere (then `build` only checks that it runs).
#   source .gpu-deps/unpack.sh is done here (pack-deps.sh --mpi); ../shared/gpu-host/README.md.
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
OUT=${OUT:-$PWD/device-out}
mkdir -p "$OUT"
phases=${*:-build check bench scaling}
has() { [[ " $phases " == *" $1 "* ]]; }
log() { echo "== $(date -u +%H:%M:%S) $*" | tee -a "$OUT/summary.txt"; }
# The tree here is a copy (its .git, if any, is not this commit's): name the commit.
if [ -f .gpu-deps/source-commit ]; then export PATHBENCH_SOURCE_COMMIT=$(cat .gpu-deps/source-commit); fi
if [ -f .gpu-deps/unpack.sh ]; then source .gpu-deps/unpack.sh >/dev/null; fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 NCCL_NVLS_ENABLE=0
MPIRUN=$(command -v mpirun.openmpi || command -v mpirun)
B=build-mpi
PB=${PB:-$B/bin/pathbench}
gpus=$(nvidia-smi -L | wc -l)
log "GPUs: $gpus, mpirun: $MPIRUN"

if has build && [ "$PB" != "$B/bin/pathbench" ]; then
  # A binary built elsewhere: it must find its libraries and run here, else build it.
  if ldd "$PB" | grep -q "not found" || ! "$PB" render --quiet --device gpu --width 8 --height 8 --spp 1 --out /tmp/pb-smoke.pfm; then
    log "the given pathbench ($PB) does not run here: $(ldd "$PB" | grep 'not found' | tr '\n' ' '): building"
    PB=$B/bin/pathbench
  else
    log "using the given pathbench $PB"
  fi
fi
if has build && [ "$PB" = "$B/bin/pathbench" ]; then
  cmake -S . -B $B -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF -DPATHBENCH_PYTHON=OFF \
        -DPATHBENCH_MPI=ON -DMPI_CXX_COMPILER=$(command -v mpicxx.openmpi || command -v mpicxx) \
        -DPATHBENCH_NCCL=${PATHBENCH_NCCL:-AUTO} \
        -DCMAKE_CUDA_ARCHITECTURES=90 > "$OUT/configure.txt" 2>&1 || { tail -30 "$OUT/configure.txt"; exit 1; }
  log "$(grep -E 'pathbench: (MPI|NCCL)' "$OUT/configure.txt" | tr '\n' ' ')"
  # pathbench first (the rest of the phases need it), then the test binaries (a failure there
  # is logged, and the tests that need them fail).
  cmake --build $B -j "$(nproc)" --target pathbench > "$OUT/build.txt" 2>&1 \
    || { grep -E "error|FAILED" -A3 "$OUT/build.txt" | head -60; exit 1; }
  cmake --build $B -j "$(nproc)" --target ${TARGETS:-pathbench-bench pathbench_unit_tests pathbench_gpu_tests \
        pathbench_gpu_stability_tests pathbench_traversal_tests} >> "$OUT/build.txt" 2>&1 \
    || { grep -E "error|FAILED" -A3 "$OUT/build.txt" | head -60; log "BUILD OF TEST TARGETS FAILED"; }
  log "build ok"
  (cd $B && ctest -L mpi --output-on-failure -j4 > "$OUT/ctest-mpi.txt" 2>&1; tail -4 "$OUT/ctest-mpi.txt")
  log "ctest -L mpi: $(grep -E 'tests passed|tests failed' "$OUT/ctest-mpi.txt")"
  (cd $B && ctest -R 'RankSplit|RunRanks' --output-on-failure > "$OUT/ctest-ranks.txt" 2>&1; tail -3 "$OUT/ctest-ranks.txt")
fi

if has gpu; then
  # GPU_TESTS: a regular expression for a subset (default: every test labelled gpu).
  (cd $B && ctest -L gpu ${GPU_TESTS:+-R "$GPU_TESTS"} --output-on-failure --timeout 300 > "$OUT/ctest-gpu.txt" 2>&1; tail -4 "$OUT/ctest-gpu.txt")
  log "ctest -L gpu ${GPU_TESTS:-}: $(grep -E 'tests passed|tests failed' "$OUT/ctest-gpu.txt")"
fi

mpi() { "$MPIRUN" --oversubscribe --bind-to none "$@"; }
same() { if cmp -s "$1" "$2"; then log "IDENTICAL $3"; else log "DIFFERENT $3"; fi; }
secs() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); r=d.get('ranks'); print(r['frame_seconds'] if r else d.get('device_seconds', d['seconds']), (r or {}).get('device_share',''), (r or {}).get('parallel_efficiency',''), (r or {}).get('reduce_seconds',''))" "$1"; }
if has check; then
  for frame in "256 256 800" "2048 2048 1024"; do
    set -- $frame
    f="render --quiet --width $1 --height $2 --spp $3 --bounces 2"
    tag=$1x$2x$3
    $PB $f --device gpu --out "$OUT/gpu1-$tag.pfm" --report "$OUT/gpu1-$tag.json"
    if [ "$1" = 256 ]; then  # the CPU alone on the big frame would take minutes
      $PB $f --device cpu --out "$OUT/cpu1-$tag.pfm" --report "$OUT/cpu1-$tag.json"
      same "$OUT/gpu1-$tag.pfm" "$OUT/cpu1-$tag.pfm" "$tag: one CPU process vs one GPU process"
    fi
    mpi -np 2 $PB $f --device gpu --out "$OUT/gpu2-$tag.pfm" --report "$OUT/gpu2-$tag.json"
    same "$OUT/gpu1-$tag.pfm" "$OUT/gpu2-$tag.pfm" "$tag: 2 GPU ranks (on $gpus GPUs) vs one GPU"
    mpi -np 1 $PB $f --device gpu --out "$OUT/hy-$tag.pfm" --report "$OUT/hy-$tag.json" : \
        -np 1 $PB $f --device cpu --out "$OUT/hy-$tag.pfm" --report "$OUT/hy-$tag.json"
    same "$OUT/gpu1-$tag.pfm" "$OUT/hy-$tag.pfm" "$tag: hybrid GPU+CPU (MPMD, dynamic) vs one GPU"
    log "$tag seconds [frame share efficiency reduce]: gpu1 $(secs "$OUT/gpu1-$tag.json") | gpu2 $(secs "$OUT/gpu2-$tag.json") | hybrid $(secs "$OUT/hy-$tag.json")"
  done
  rm -f "$OUT"/*.pfm
fi
# Interleaved rounds at 256x256x800 (REPS rounds) and 2048x2048x1024 (REPS_BIG): one GPU
# process (DIR/gpu-<width>-<i>.json), then for each arm the hybrid (1 GPU + 1 CPU rank, MPMD,
# dynamic) with PATHBENCH_GPU_RENDER_CACHE=1 (arms hy, on) or 0 (off) on both ranks
# (DIR/<arm>-<width>-<i>.json); each image against the GPU's, byte for byte.
hybrid_rounds() {  # DIR REPS REPS_BIG ARM...
  local dir=$1 reps=$2 big=$3; shift 3
  local arms="$*" frame f n i arm
  mkdir -p "$dir"
  for frame in "256 256 800" "2048 2048 1024"; do
    set -- $frame
    f="render --quiet --width $1 --height $2 --spp $3 --bounces 2"
    n=$reps; [ "$1" = 2048 ] && n=$big
    for i in $(seq 1 $n); do
      $PB $f --device gpu --out "$OUT/g.pfm" --report "$dir/gpu-$1-$i.json"
      for arm in $arms; do
        PATHBENCH_GPU_RENDER_CACHE=$([ $arm = off ] && echo 0 || echo 1) mpi -x PATHBENCH_GPU_RENDER_CACHE \
            -np 1 $PB $f --device gpu --out "$OUT/h.pfm" --report "$dir/$arm-$1-$i.json" : \
            -np 1 $PB $f --device cpu --out "$OUT/h.pfm" --report "$dir/$arm-$1-$i.json"
        same "$OUT/g.pfm" "$OUT/h.pfm" "$1x$2x$3 round $i: hybrid ($arm) vs one GPU"
      done
    done
  done
  rm -f "$OUT"/*.pfm
}
if has hybrid; then
  # Both timed from the frame's start to the film on the host: the GPU's `seconds` (host
  # clock around its frame) plus its film download, against the hybrid's frame_seconds
  # (common start to the film reduced on rank 0).
  hybrid_rounds "$OUT/hybrid" "${REPS:-5}" "${REPS:-5}" hy
  python3 tools/hybrid_timing.py "$OUT/hybrid" | tee "$OUT/hybrid.md" | tee -a "$OUT/summary.txt"
fi
if has bench; then
  # Every GPU render benchmark of the quick preset: 1 process, then 2 ranks (one frame
  # over both per iteration); the film hashes must agree, benchmark by benchmark.
  q="--preset quick --benchmark_filter=render/gpu/ --benchmark_min_time=0.2"
  $B/bin/pathbench-bench $q --benchmark_out="$OUT/bench-gpu1.json" > "$OUT/bench-gpu1.txt" 2>&1
  mpi -np 2 $B/bin/pathbench-bench $q --benchmark_out="$OUT/bench-gpu2.json" > "$OUT/bench-gpu2.txt" 2>&1
  log "bench over ranks: $(python3 - "$OUT/bench-gpu1.json" "$OUT/bench-gpu2.json" <<'EOF_PY'
import json, sys
one, two = (json.load(open(p)) for p in sys.argv[1:])
h1, h2 = one["context"]["film_hashes"], two["context"]["film_hashes"]
rows = {b["name"]: b for b in two["benchmarks"]}
same = sum(h1[k] == h2.get(k) for k in h1)
print(f"{same}/{len(h1)} GPU render benchmarks with one process's film hash over {two['context']['mpi_ranks']} ranks;",
      "; ".join(f"{k.split('/')[2]}/{k.split('/')[-1]}: {rows[k + '/manual_time']['real_time']:.2f} ms, efficiency "
                f"{rows[k + '/manual_time']['parallel_efficiency']:.2f}" for k in sorted(h2)))
EOF_PY
)"
fi
if has reduce; then
  # The GPU ranks' reduction, NCCL against MPI (PATHBENCH_FILM_REDUCE=mpi), 2 GPU ranks,
  # interleaved rounds (REPS, 3 here by default): frame and reduce seconds of each.
  mkdir -p "$OUT/reduce"
  for frame in "256 256 800" "2048 2048 1024"; do
    set -- $frame
    f="render --quiet --width $1 --height $2 --spp $3 --bounces 2 --device gpu"
    for i in $(seq 1 ${REDUCE_REPS:-3}); do
      for how in nccl mpi; do
        PATHBENCH_FILM_REDUCE=$how mpi -np 2 $PB $f --out "$OUT/r.pfm" --report "$OUT/reduce/$how-$1-$i.json"
      done
    done
  done
  rm -f "$OUT/r.pfm"
  for p in "$OUT"/reduce/*.json; do
    log "reduce $(basename "$p" .json): $(python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['ranks']; print(f\"frame {r['frame_seconds']:.5f} s reduce {r['reduce_seconds']:.5f} s ({r['reduction']['gpu_ranks']}) parts\", [p.get('reduce_parts') for p in r['per_rank']][0])" "$p")"
  done
fi
if has cache; then
  # The hybrid with gpu::render's kept setup (on) and without it (off), against one GPU.
  hybrid_rounds "$OUT/ab/cache" "${CACHE_REPS:-5}" "${CACHE_REPS_BIG:-3}" on off
fi
if has bands; then
  # 2 GPU ranks: the film reduced at the end (1 band) against band by band while tracing
  # (auto, and 4 at the small frame, where auto keeps one band), interleaved rounds.
  mkdir -p "$OUT/ab/bands"
  for frame in "256 256 800" "2048 2048 1024"; do
    set -- $frame
    f="render --quiet --width $1 --height $2 --spp $3 --bounces 2 --device gpu"
    arms="1 auto"; [ "$1" = 256 ] && arms="1 auto 4"
    for i in $(seq 1 ${BANDS_REPS:-3}); do
      for b in $arms; do
        PATHBENCH_REDUCE_BANDS=$b mpi -x PATHBENCH_REDUCE_BANDS -np 2 $PB $f --out "$OUT/b.pfm" \
            --report "$OUT/ab/bands/b$b-$1-$i.json"
      done
    done
  done
  rm -f "$OUT"/*.pfm
fi
if has cache || has bands; then
  python3 tools/mpi_scaling_ab.py "$OUT/ab" | tee "$OUT/ab.md" | tee -a "$OUT/summary.txt"
fi
if has scaling; then
  rec=(); [ "${RECORD:-0}" = 1 ] && rec=(--record ${PATHBENCH_SOURCE_COMMIT:+--commit "$PATHBENCH_SOURCE_COMMIT"})
  # Each CPU rank's film hash (before the reduction) in the study's JSON (rank_film_hashes_all).
  export PATHBENCH_RANK_FILM_HASH=1
  PYTHONUNBUFFERED=1 python3 tools/mpi_scaling.py --pathbench $PB --mpirun "$MPIRUN" --gpus "$gpus" \
      --mpi-arg=-x --mpi-arg=PATHBENCH_RANK_FILM_HASH \
      --cpu-ranks "${CPU_RANKS-1,2,4}" --reps "${SCALING_REPS:-3}" --hybrid-rounds "${HYBRID_ROUNDS:-${REPS:-5}}" \
      --out-dir "$OUT/scaling" "${rec[@]}" > "$OUT/scaling.txt" 2>&1
  log "scaling: $(grep -E '^\||NOT IDENTICAL|recorded' "$OUT/scaling.txt")"
fi
if has repeat; then
  # The NOT IDENTICAL hunt (issue 30): CPU ranks (static, and dynamic), image bytes and film
  # hash of every run against one CPU process's, REPEAT_RUNS times each.
  mkdir -p "$OUT/repeat"
  f="render --quiet --width 256 --height 256 --spp 800 --bounces 2 --device cpu"
  $PB $f --out "$OUT/repeat/one.pfm" --report "$OUT/repeat/one.json"
  ref=$(sha256sum < "$OUT/repeat/one.pfm"); refh=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['film_hash'])" "$OUT/repeat/one.json")
  diff=0; total=0
  for i in $(seq 1 ${REPEAT_RUNS:-8}); do
    for np in 2 4; do
      for bal in static dynamic; do
        mpi -np $np $PB $f --balance $bal --out "$OUT/repeat/x.pfm" --report "$OUT/repeat/x.json"
        total=$((total + 1))
        h=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['film_hash'])" "$OUT/repeat/x.json")
        if [ "$(sha256sum < "$OUT/repeat/x.pfm")" != "$ref" ] || [ "$h" != "$refh" ]; then
          diff=$((diff + 1)); cp "$OUT/repeat/x.pfm" "$OUT/repeat/diff-$i-$np-$bal.pfm"; cp "$OUT/repeat/x.json" "$OUT/repeat/diff-$i-$np-$bal.json"
          log "repeat $i -np $np $bal: DIFFERENT (film hash $h vs $refh)"
        fi
      done
    done
  done
  log "repeat: $diff of $total CPU-rank runs (256x256x800, -np 2 and 4, static and dynamic) differ from one process"
  rm -f "$OUT"/repeat/*.pfm
fi
if has hunt; then
  # Issue 30's film difference: 3 CPU ranks (static, the study's split and threads), each
  # run's film hash, each rank's own film hash and traced Embree layout, and rank 0's layout
  # probe (the layout every rank traces), against one CPU process; then a scene above the
  # tiny-scene limit (Embree's packets answer the pixel strategy's rays: the ranks' samples
  # are whole batches of 16), static and dynamic.
  mkdir -p "$OUT/hunt"
  export PATHBENCH_RANK_FILM_HASH=1
  f="render --quiet --width 256 --height 256 --spp 800 --bounces 2 --device cpu"
  $PB $f --out "$OUT/hunt/one.pfm" --report "$OUT/hunt/one.json"
  line() {  # REPORT: film hash, per-rank film hashes, per-rank layouts, rank 0's probe (quads/triangles)
    python3 - "$1" <<'EOF_PY'
import json, sys
r = json.load(open(sys.argv[1]))
ranks = (r.get("ranks") or {}).get("per_rank", [])
lay = r.get("embree_layout") or {}
p = lay.get("probe_ns_per_ray") or {}
ratio = f"{p['quads'] / p['triangles']:.3f}" if p.get("triangles") else "-"
print(r["film_hash"], ",".join(str(e.get("film_hash")) for e in ranks) or "-",
      ",".join(str((e.get("embree_layout") or {}).get("used")) for e in ranks) or lay.get("used"), "probe", ratio,
      "spp", ",".join(f"{e['samples_per_pixel']:g}" for e in ranks) or "-")
EOF_PY
  }
  ref=$(line "$OUT/hunt/one.json" | cut -d' ' -f1); refimg=$(sha256sum < "$OUT/hunt/one.pfm")
  echo "one $(line "$OUT/hunt/one.json")" > "$OUT/hunt/runs.txt"
  diff=0; runs=${HUNT_RUNS:-30}
  for i in $(seq 1 $runs); do
    mpi -x PATHBENCH_RANK_FILM_HASH -np 3 $PB $f --balance static --out "$OUT/hunt/x.pfm" --report "$OUT/hunt/x.json"
    l=$(line "$OUT/hunt/x.json"); echo "np3 $i $l" >> "$OUT/hunt/runs.txt"
    if [ "${l%% *}" != "$ref" ] || [ "$(sha256sum < "$OUT/hunt/x.pfm")" != "$refimg" ]; then
      diff=$((diff + 1)); cp "$OUT/hunt/x.json" "$OUT/hunt/diff-$i.json"; log "hunt $i: DIFFERENT: $l (one process: $ref)"
    fi
  done
  log "hunt: $diff of $runs runs of 3 CPU ranks (256x256x800, static) differ from one process ($ref); $(grep -c 'triangles' "$OUT/hunt/runs.txt") traced triangles; rank 0's probe quads/triangles $(awk '/^np3/ {print $7}' "$OUT/hunt/runs.txt" | sort -n | sed -n '1p;$p' | tr '\n' ' ')(min, max)"
  g="render --quiet --width 256 --height 256 --spp 100 --bounces 2 --device cpu --scene paper-cornell-ico:3"
  $PB $g --out "$OUT/hunt/ico1.pfm" --report "$OUT/hunt/ico1.json"
  ref=$(line "$OUT/hunt/ico1.json" | cut -d' ' -f1); n=0; d=0
  for i in $(seq 1 ${HUNT_ICO_RUNS:-3}); do
    for bal in static dynamic; do
      mpi -x PATHBENCH_RANK_FILM_HASH -np 3 $PB $g --balance $bal --out "$OUT/hunt/x.pfm" --report "$OUT/hunt/x.json"
      l=$(line "$OUT/hunt/x.json"); echo "ico3 $bal $i $l" >> "$OUT/hunt/runs.txt"; n=$((n + 1))
      if [ "${l%% *}" != "$ref" ] || ! cmp -s "$OUT/hunt/ico1.pfm" "$OUT/hunt/x.pfm"; then
        d=$((d + 1)); log "hunt ico:3 $bal $i: DIFFERENT: $l (one process: $ref)"
      fi
    done
  done
  log "hunt: paper-cornell-ico:3 256x256x100, 3 CPU ranks (static 48 + 32 + 20 a pixel, and dynamic): $d of $n differ from one process ($ref)"
  unset PATHBENCH_RANK_FILM_HASH
  rm -f "$OUT"/hunt/*.pfm
fi
if has largemesh; then
  # The suite's large mesh (13.3 M triangles, Loop-subdivided armadillo) on one GPU and over
  # every GPU (one rank each): frame, reduction and film hash.
  mkdir -p "$OUT/largemesh"
  f="render --quiet --scene scenes/suite/large-mesh.json --width 256 --height 256 --spp 800 --bounces 2 --sampling nee --device gpu"
  $PB $f --out "$OUT/lm1.pfm" --report "$OUT/largemesh/gpu1.json"
  mpi -np "$gpus" $PB $f --out "$OUT/lmN.pfm" --report "$OUT/largemesh/gpu$gpus.json"
  same "$OUT/lm1.pfm" "$OUT/lmN.pfm" "large-mesh 256x256x800: $gpus GPU ranks vs one GPU"
  log "large-mesh seconds [frame share efficiency reduce]: 1 GPU $(secs "$OUT/largemesh/gpu1.json") + download $(python3 -c "import json,sys; print(json.load(open(sys.argv[1])).get('film_download_seconds'))" "$OUT/largemesh/gpu1.json") | $gpus GPUs $(secs "$OUT/largemesh/gpu$gpus.json")"
  rm -f "$OUT"/lm*.pfm
fi
