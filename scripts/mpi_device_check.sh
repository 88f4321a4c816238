#!/usr/bin/env bash
# MPI ranks on a GPU host (issues 13, 30, 31), for the device machine: build with MPI (and
# NCCL where found: PATHBENCH_NCCL=ON to insist), run the mpi tests, check that 2 GPU ranks (on one GPU when only one is visible) and the
# CPU+GPU hybrid give the one-GPU image byte for byte, that pathbench-bench's GPU render
# benchmarks over 2 ranks give one process's film hashes, and run tools/mpi_scaling.py.
# Everything lands under $OUT (default ./device-out). Phases: build gpu check bench reduce scaling
# hybrid (gpu: ctest -L gpu in the same build, GPU_TESTS=regex for a subset; hybrid: one GPU
# alone against the hybrid, interleaved rounds, REPS=5 by default; scaling: tools/mpi_scaling.py
# --gpus <all visible>, SCALING_REPS=3, CPU_RANKS=1,2,4). TARGETS: what to build.
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
PB=$B/bin/pathbench
gpus=$(nvidia-smi -L | wc -l)
log "GPUs: $gpus, mpirun: $MPIRUN"

if has build; then
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
if has hybrid; then
  # Interleaved rounds: one GPU process, then the hybrid (1 GPU + 1 CPU rank), same frame.
  # Both timed from the frame's start to the film on the host: the GPU's `seconds` (host
  # clock around its frame) plus its film download, against the hybrid's frame_seconds
  # (common start to the film reduced on rank 0).
  mkdir -p "$OUT/hybrid"
  for frame in "256 256 800" "2048 2048 1024"; do
    set -- $frame
    f="render --quiet --width $1 --height $2 --spp $3 --bounces 2"
    for i in $(seq 1 ${REPS:-5}); do
      $PB $f --device gpu --out "$OUT/g.pfm" --report "$OUT/hybrid/gpu-$1-$i.json"
      mpi -np 1 $PB $f --device gpu --out "$OUT/h.pfm" --report "$OUT/hybrid/hy-$1-$i.json" : \
          -np 1 $PB $f --device cpu --out "$OUT/h.pfm" --report "$OUT/hybrid/hy-$1-$i.json"
      same "$OUT/g.pfm" "$OUT/h.pfm" "$1x$2x$3 round $i: hybrid vs one GPU"
    done
  done
  rm -f "$OUT"/*.pfm
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
if has scaling; then
  PYTHONUNBUFFERED=1 python3 tools/mpi_scaling.py --pathbench $PB --mpirun "$MPIRUN" --gpus "$gpus" \
      --cpu-ranks "${CPU_RANKS-1,2,4}" --reps "${SCALING_REPS:-3}" --hybrid-rounds "${REPS:-5}" \
      --out-dir "$OUT/scaling" > "$OUT/scaling.txt" 2>&1
  log "scaling: $(grep -E '^\||NOT IDENTICAL' "$OUT/scaling.txt")"
fi
