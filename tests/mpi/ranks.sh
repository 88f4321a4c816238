#!/bin/sh
# `pathbench render` over MPI ranks (issue 13), one case per CTest test:
#   sh ranks.sh CASE PATHBENCH MPIEXEC DIR
# np2, np3        mpirun -np N gives the one-process image byte for byte (static and dynamic)
# mpmd_threads    two MPMD lines differing only in --threads, dynamic chunks: same bytes
# mpmd_mismatch   MPMD lines differing in --spp: refused, exit 2, no image
# failing_rank    rank 1 cannot read its scene: every rank ends, exit 2, rank 1's message
# hybrid_no_gpu   --device hybrid where no GPU can run: exit 2, the GPU rank's message
# killed_rank     rank 1 SIGKILLed mid-render: the run ends within 30 s, non-zero, no image
# accuracy        `accuracy --quick`: the ranks' reference equals the one-process reference
# reproduce       `reproduce --device cpu --spp 16`: the ranks' images equal one process's
# bench           `mpirun -np 2 pathbench-bench` (and `pathbench bench --out`): each render
#                 iteration is a frame over both ranks, with one process's film hashes
# gpu2, hybrid    (CUDA builds; skipped, status 77, without a usable GPU) 2 GPU ranks, and
#                 --device hybrid (GPU + CPU ranks, dynamic), give the one-GPU image
# gpu_shared      (CUDA builds; skipped without a GPU) 3 GPU ranks on the visible GPUs, more
#                 ranks than GPUs where there are fewer than 3: the one-GPU image; the report
#                 says how the GPU ranks' films were reduced (NCCL or MPI, and why)
# gpu2_bands      (CUDA builds; skipped without a GPU) 2 GPU ranks with PATHBENCH_REDUCE_BANDS=4
#                 (on 2 GPUs with NCCL: the film reduced band by band while the next band
#                 traces), with 3 (uneven rows) and 64 (more bands than rows: one a row), and
#                 a bad count refused (exit 2): the one-GPU image byte for byte
# tcp             as between nodes: MPI's TCP transport alone (--mca btl self,tcp, no shared
#                 memory), static and dynamic: the one-process image byte for byte
# tcp_killed_rank a rank SIGKILLed over TCP alone: the run ends within 30 s with a message
#                 naming the lost process, no image
# idle_rank       3 ranks, dynamic, a frame of 16 units (8 rows x 2 spp) and chunks of at least
#                 8 (a rank's probe): a rank is granted nothing, sends nothing (send_film_rows),
#                 and the image is still one process's byte for byte
# layout_agree    3 CPU ranks under --embree-layout auto: every rank traced rank 0's probed
#                 layout, probe times and all (each rank once timed its own probe beside the
#                 others' start: one rank of three picked triangles, a film other than one
#                 process's with the same image bytes; issue 30), and the film is one process's
# rank_film_hash  PATHBENCH_RANK_FILM_HASH=1: each CPU rank's own film hash in its report entry,
#                 none for a rank granted no samples; another value (yes) refused, exit 2, no image
# packets        paper-cornell-ico:1 (94 triangles: above the tiny test, so Embree's packets
#                 answer the pixel strategy's rays, and a ray at an edge by its packet mates),
#                 40 spp over 3 ranks, static and dynamic: each rank's samples are whole
#                 batches of 16 at batch boundaries (static: 16 + 16 + 8 a pixel, where the
#                 plain split was 14 + 13 + 13), so its packets are one process's; the film
#                 is one process's (the pixel strategy; the wavefront's packets follow the
#                 threads' timing, in one process as over ranks: docs/mpi.md)
# Small frames (64x64): each case takes a few seconds on 2 cores.
set -u
case_name=$1
pb=$2
mpiexec=$3
dir=$4
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir" || exit 1
# CI runs as root on 2 cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# PB_MPI_ARGS: more mpirun options (two_nodes.sh: the hostfile and launch agent of its
# namespaces); PB_TCP_ARGS: the TCP-only options in place of the loopback's.
mpi="$mpiexec --oversubscribe --bind-to none ${PB_MPI_ARGS:-}"
base="render --quiet --width 64 --height 64 --bounces 2"
frame="$base --spp 24"
fail() { echo "ranks.sh $case_name: $*" >&2; exit 1; }
one() { "$pb" $frame --threads 1 --out one.pfm --report one.json || fail "one-process render failed"; }
film_hash() { grep -o '"film_hash": "[^"]*"' "$1"; }
same() { cmp -s one.pfm "$1" || fail "$1 differs from the one-process image"; }
# Runs mpirun, keeps its stderr in err.txt and its status in $status, bounded by 60 s.
run() {
  timeout 60 $mpi "$@" >out.txt 2>err.txt
  status=$?
}
refused() {  # STATUS-WANTED REGEX FILE
  [ "$status" = "$1" ] || { cat err.txt >&2; fail "exit status $status, wanted $1"; }
  grep -Eq "$2" err.txt || { cat err.txt >&2; fail "no message matching '$2'"; }
  [ ! -e "$3" ] || fail "$3 was written"
  ls | grep -q '\.tmp' && fail "a temporary file was left: $(ls)"
  return 0
}

# Rank 1 is a shell that starts pathbench (which joins the run as rank 1) and kills it: the
# run ends within 30 s, non-zero, naming the killed process, with no image. $@: mpirun options.
killed() {
  start=$(date +%s)
  run "$@" -np 1 "$pb" $base --spp 100000 --out x.pfm : \
      -np 1 sh -c "\"$pb\" $base --spp 100000 --out x.pfm & p=\$!; sleep 2; kill -9 \$p; wait \$p"
  elapsed=$(( $(date +%s) - start ))
  [ "$status" != 0 ] || fail "the run succeeded"
  [ "$status" != 124 ] || fail "the run hung (killed by timeout after 60 s)"
  [ "$elapsed" -le 30 ] || fail "the run took $elapsed s to end"
  grep -q "exited on signal 9\|Exit code: *137\|signal 9" err.txt || { cat err.txt >&2; fail "no word of the killed rank"; }
  refused "$status" "." x.pfm
}
# Between nodes there is no shared memory: TCP alone, on the loopback interface here.
tcp=${PB_TCP_ARGS:-"--mca btl self,tcp --mca btl_tcp_if_include lo --mca pml ob1 --mca osc ^sm,rdma"}

case $case_name in
  tcp)
    one
    for balance in static dynamic; do
      run $tcp -np 2 "$pb" $frame --balance $balance --out $balance.pfm --report $balance.json
      [ "$status" = 0 ] || { cat err.txt >&2; fail "TCP only, --balance $balance: status $status"; }
      same $balance.pfm
      [ "$(film_hash one.json)" = "$(film_hash $balance.json)" ] || fail "TCP only: film_hash differs"
    done ;;
  tcp_killed_rank) killed $tcp ;;
  gpu_shared)
    "$pb" $frame --device gpu --out gpu.pfm --report gpu.json 2>gpu.err || { cat gpu.err; echo "no usable GPU: skipped"; exit 77; }
    run -np 3 "$pb" $frame --device gpu --out x.pfm --report x.json
    [ "$status" = 0 ] || { cat err.txt >&2; fail "status $status"; }
    cmp -s gpu.pfm x.pfm || fail "3 GPU ranks: x.pfm differs from the one-GPU image"
    [ "$(film_hash gpu.json)" = "$(film_hash x.json)" ] || fail "3 GPU ranks: film_hash differs"
    grep -q '"gpu_ranks": "\(nccl\|mpi\)"' x.json || fail "the report does not say how the films were reduced" ;;
  gpu2_bands)
    bframe="render --quiet --width 64 --height 50 --bounces 2 --spp 24 --device gpu"
    "$pb" $bframe --out gpu.pfm --report gpu.json 2>gpu.err || { cat gpu.err; echo "no usable GPU: skipped"; exit 77; }
    for bands in 4 3 64; do
      export PATHBENCH_REDUCE_BANDS=$bands
      run -x PATHBENCH_REDUCE_BANDS -np 2 "$pb" $bframe --out b$bands.pfm --report b$bands.json
      [ "$status" = 0 ] || { cat err.txt >&2; fail "PATHBENCH_REDUCE_BANDS=$bands: status $status"; }
      cmp -s gpu.pfm b$bands.pfm || fail "PATHBENCH_REDUCE_BANDS=$bands: the image differs from the one-GPU image"
      [ "$(film_hash gpu.json)" = "$(film_hash b$bands.json)" ] || fail "PATHBENCH_REDUCE_BANDS=$bands: film_hash differs"
      # Through NCCL (2 GPUs) the report names the bands, at most one a row; through MPI one.
      if grep -q '"gpu_ranks": "nccl"' b$bands.json; then
        want=$bands; [ $bands -gt 50 ] && want=50
        grep -q "\"bands\": $want," b$bands.json || fail "PATHBENCH_REDUCE_BANDS=$bands: the report does not say $want bands"
      fi
    done
    export PATHBENCH_REDUCE_BANDS=lots
    run -x PATHBENCH_REDUCE_BANDS -np 2 "$pb" $bframe --out bad.pfm
    unset PATHBENCH_REDUCE_BANDS
    if grep -q '"gpu_ranks": "nccl"' b4.json; then refused 2 "PATHBENCH_REDUCE_BANDS='lots'" bad.pfm; fi ;;
  np2|np3)
    n=${case_name#np}
    one
    for balance in static dynamic; do
      run -np "$n" "$pb" $frame --balance $balance --out $balance.pfm --report $balance.json
      [ "$status" = 0 ] || { cat err.txt >&2; fail "mpirun -np $n --balance $balance: status $status"; }
      same $balance.pfm
      grep -q "\"count\": $n" $balance.json || fail "the report has no ranks section of $n ranks"
      grep -q '"parallel_efficiency"' $balance.json || fail "the report has no parallel efficiency"
      [ -n "$(film_hash one.json)" ] && [ "$(film_hash one.json)" = "$(film_hash $balance.json)" ] ||
        fail "film_hash of $n ranks ($(film_hash $balance.json)) is not one process's ($(film_hash one.json))"
    done ;;
  idle_rank)
    tiny="render --quiet --width 8 --height 8 --bounces 2 --spp 2"
    "$pb" $tiny --out one.pfm --report one.json || fail "one-process render failed"
    run -np 3 "$pb" $tiny --balance dynamic --out x.pfm --report x.json
    [ "$status" = 0 ] || { cat err.txt >&2; fail "status $status"; }
    same x.pfm
    [ "$(film_hash one.json)" = "$(film_hash x.json)" ] || fail "film_hash differs"
    grep -q '"samples": 0,' x.json || fail "no rank was idle: the case no longer tests a rank without rows" ;;
  layout_agree)
    frame="$base --spp 48"  # 3 batches of 16: every rank traces (run/ranks.h, kSampleBatch)
    one
    run -np 3 "$pb" $frame --balance static --out x.pfm --report x.json
    [ "$status" = 0 ] || { cat err.txt >&2; fail "status $status"; }
    same x.pfm
    [ "$(film_hash one.json)" = "$(film_hash x.json)" ] || fail "film_hash differs"
    python3 - x.json <<'EOF_PY' || fail "the ranks did not all trace rank 0's measured layout"
import json, sys
r = json.load(open(sys.argv[1]))
ranks = r["ranks"]["per_rank"]
assert len(ranks) == 3 and r["embree_layout"]["asked"] == "auto", r["embree_layout"]
layouts = [e.get("embree_layout") for e in ranks]
assert layouts[0] is not None and layouts[0]["probe_ns_per_ray"], layouts[0]
for i, l in enumerate(layouts):
    assert l == layouts[0], f"rank {i} traced {l}, rank 0 {layouts[0]}"
print("ranks.sh layout_agree: every rank:", layouts[0]["used"], layouts[0]["probe_ns_per_ray"])
EOF_PY
    ;;
  rank_film_hash)
    export PATHBENCH_RANK_FILM_HASH=1
    run -x PATHBENCH_RANK_FILM_HASH -np 2 "$pb" $frame --out x.pfm --report x.json
    [ "$status" = 0 ] || { cat err.txt >&2; fail "status $status"; }
    [ "$(grep -c '"film_hash": "fnv1a64:' x.json)" = 3 ] || fail "not a film hash for each rank and the frame"
    # A rank granted nothing (idle_rank's frame) hashes nothing: its zero film's pass would
    # only delay the others' reduction.
    run -x PATHBENCH_RANK_FILM_HASH -np 3 "$pb" render --quiet --width 8 --height 8 --bounces 2 --spp 2 \
      --balance dynamic --out z.pfm --report z.json
    [ "$status" = 0 ] || { cat err.txt >&2; fail "idle rank: status $status"; }
    python3 - z.json <<'EOF_PY' || fail "a rank that traced nothing hashed its film, or a rank that traced did not"
import json, sys
ranks = json.load(open(sys.argv[1]))["ranks"]["per_rank"]
assert any(e["samples"] == 0 for e in ranks), "no rank was idle"
for e in ranks:
    assert ("film_hash" in e) == (e["samples"] > 0), e
EOF_PY
    export PATHBENCH_RANK_FILM_HASH=yes
    run -x PATHBENCH_RANK_FILM_HASH -np 2 "$pb" $frame --out y.pfm
    unset PATHBENCH_RANK_FILM_HASH
    refused 2 "PATHBENCH_RANK_FILM_HASH='yes': expected 1" y.pfm ;;
  packets)
    ico="render --quiet --width 64 --height 64 --bounces 2 --spp 40 --scene paper-cornell-ico:1 --embree-layout triangles"
    "$pb" $ico --threads 2 --out one.pfm --report one.json || fail "one-process render failed"
    for balance in static dynamic; do
      run -np 3 "$pb" $ico --threads 1 --balance $balance --out x.pfm --report x.json
      [ "$status" = 0 ] || { cat err.txt >&2; fail "$balance: status $status"; }
      if [ $balance = static ]; then
        python3 - x.json <<'EOF_PY' || fail "static: the ranks' samples are not whole batches of 16"
import json, sys
spp = [e["samples_per_pixel"] for e in json.load(open(sys.argv[1]))["ranks"]["per_rank"]]
assert spp == [16, 16, 8], spp
EOF_PY
      fi
      same x.pfm
      [ "$(film_hash one.json)" = "$(film_hash x.json)" ] || fail "$balance: film_hash differs"
    done ;;
  mpmd_threads)
    one
    run -np 1 "$pb" $frame --balance dynamic --threads 2 --out mpmd.pfm : -np 1 "$pb" $frame --balance dynamic --threads 1 --out mpmd.pfm
    [ "$status" = 0 ] || { cat err.txt >&2; fail "status $status"; }
    same mpmd.pfm ;;
  mpmd_mismatch)
    run -np 1 "$pb" $frame --out x.pfm : -np 1 "$pb" $frame --out x.pfm --seed 7
    refused 2 "rank 1 of 2: its settings differ from rank 0's: seed=7 here, seed=0 on rank 0" x.pfm ;;
  failing_rank)
    run -np 1 "$pb" $frame --out x.pfm : -np 1 "$pb" $frame --out x.pfm --scene no-such-scene.json
    refused 2 "rank 1 of 2: .*no-such-scene.json" x.pfm ;;
  hybrid_no_gpu)
    run -np 2 "$pb" $frame --device hybrid --out x.pfm
    refused 2 "rank 0 of 2: --device gpu: " x.pfm ;;
  killed_rank) killed ;;
  accuracy)
    "$pb" accuracy --quick --no-report-tool --out-dir one >one.log 2>&1 || { cat one.log >&2; fail "one process failed"; }
    run -np 2 "$pb" accuracy --quick --no-report-tool --out-dir two
    [ "$status" = 0 ] || { cat err.txt >&2; fail "status $status"; }
    for f in one/reference-*.pfm; do
      cmp -s "$f" "two/${f#one/}" || fail "two/${f#one/} differs from the one-process reference"
    done
    grep -q '"parallel_efficiency"' two/reference-*.json || fail "the reference's report has no ranks section" ;;
  reproduce)
    "$pb" reproduce --device cpu --spp 16 --budget 0 --quiet --out-dir one >one.log 2>&1 || { cat one.log >&2; fail "one process failed"; }
    run -np 2 "$pb" reproduce --device cpu --spp 16 --budget 0 --quiet --out-dir two
    [ "$status" = 0 ] || { cat err.txt >&2; fail "status $status"; }
    n=0
    for f in one/paper-cornell-cpu-*.pfm one/paper-cornell-cpu-*.png; do
      [ -e "$f" ] || continue
      cmp -s "$f" "two/${f#one/}" || fail "two/${f#one/} differs from the one-process image"
      n=$((n + 1))
    done
    [ $n -ge 2 ] || fail "no images to compare"
    grep -q '"parallel_efficiency"' two/paper-cornell-report.json || fail "the rows' reports have no ranks section" ;;
  bench)
    bb=$(dirname "$pb")/pathbench-bench
    [ -x "$bb" ] || { echo "no pathbench-bench in this build: skipped"; exit 77; }
    quick="--preset quick --benchmark_min_time=0.01"
    "$bb" $quick --benchmark_filter=render/cpu/ --benchmark_out=one.json >one.log 2>&1 ||
      { cat one.log >&2; fail "one process failed"; }
    run -np 2 "$bb" $quick --benchmark_filter=render/cpu/ --benchmark_out=two.json
    [ "$status" = 0 ] || { cat err.txt >&2; fail "pathbench-bench over 2 ranks: status $status"; }
    run -np 2 "$pb" bench $quick --out cli.json --benchmark_filter=render/cpu/pixel
    [ "$status" = 0 ] || { cat err.txt >&2; fail "pathbench bench over 2 ranks: status $status"; }
    python3 - one.json two.json cli.json <<'EOF_PY' || fail "the benchmark JSON of the ranks is not one process's"
import json, sys
one, two, cli = (json.load(open(p)) for p in sys.argv[1:])
h1, h2, hc = (j["context"]["film_hashes"] for j in (one, two, cli))
assert len(h1) == 4, f"expected pixel/wavefront x uniform/nee, got {sorted(h1)}"
assert h2 == h1, f"2 ranks {h2} != 1 process {h1}"
assert len(hc) == 2 and all(hc[k] == h1[k] for k in hc), f"pathbench bench over 2 ranks {hc} != {h1}"
assert one["context"]["mpi_ranks"] == "1" and two["context"]["mpi_ranks"] == "2" and cli["context"]["mpi_ranks"] == "2"
for b in two["benchmarks"] + cli["benchmarks"]:
    assert b["ranks"] == 2 and 0 < b["parallel_efficiency"] <= 1 and b["load_balance"] >= 1, b
print("ranks.sh bench: film hashes of 2 ranks = 1 process:", ", ".join(sorted(h1)))
EOF_PY
    [ "$(ls | grep -c '\.tmp')" = 0 ] || fail "a temporary file was left: $(ls)" ;;
  gpu2|hybrid)
    "$pb" $frame --device gpu --out gpu.pfm 2>gpu.err || { cat gpu.err; echo "no usable GPU: skipped"; exit 77; }
    if [ $case_name = gpu2 ]; then run -np 2 "$pb" $frame --device gpu --out x.pfm
    else run -np 2 "$pb" $frame --device hybrid --out x.pfm --report x.json; fi
    [ "$status" = 0 ] || { cat err.txt >&2; fail "status $status"; }
    cmp -s gpu.pfm x.pfm || fail "x.pfm differs from the one-GPU image" ;;
  *) fail "unknown case" ;;
esac
echo "ranks.sh $case_name: ok"
