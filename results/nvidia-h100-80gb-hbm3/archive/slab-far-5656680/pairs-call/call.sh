#!/usr/bin/env bash
# Issue 32, interleaved against main's GPU code (5656680), in one binary (the new tree): far = the slab
# test's far end in one DPX instruction (slab_far); pairs = that and the binary BVH's nodes in
# sibling pairs (PATHBENCH_GPU_BVH_PAIRS=1: a node's two inner children in one 128-byte line).
# Both builds made on the GPU host; then the new tree's host traversal tests.
set -u
source .gpu-deps/unpack.sh > /dev/null
export PATH=$PATH:/usr/local/cuda/bin
c=.wt-carry/ab2
rm -rf /tmp/src-base && mkdir -p /tmp/src-base
tar --exclude=./.wt-carry --exclude=./.gpu-deps --exclude=./.git -cf - . | tar -xf - -C /tmp/src-base
(cd /tmp/src-base && patch -s -R -p1 < "$OLDPWD/$c/new.patch") || { echo "the patch does not reverse"; exit 1; }
build() {  # SRC NAME
  cmake -S "$1" -B "/tmp/b-$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
    -DPATHBENCH_MPI=OFF -DPATHBENCH_NCCL=OFF -DPATHBENCH_PYTHON=OFF -DPATHBENCH_TESTS=OFF \
    -DCMAKE_CUDA_ARCHITECTURES=90 > "/tmp/configure-$2.log" 2>&1 &&
  cmake --build "/tmp/b-$2" -j 6 --target pathbench > "$OUT/build-$2.log" 2>&1
  echo "build $2 rc=$? at ${SECONDS}s"
  mkdir -p "/tmp/pb/$2/bin" && cp "/tmp/b-$2/bin/pathbench" "/tmp/pb/$2/bin/"
}
build /tmp/src-base base &
build "$PWD" new &
# The new tree's host tests of the change (slab_far, sibling pairs) and of the traversals.
(cmake -S . -B /tmp/b-tests -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=OFF -DPATHBENCH_OIIO=OFF -DPATHBENCH_MPI=OFF \
   -DPATHBENCH_PYTHON=OFF > /tmp/configure-tests.log 2>&1 &&
 cmake --build /tmp/b-tests -j 4 --target pathbench_traversal_tests > "$OUT/build-tests.log" 2>&1; echo "build tests rc=$?") &
wait
timeout 100 /tmp/b-tests/tests/gpu/pathbench_traversal_tests > "$OUT/traversal-tests.txt" 2>&1
echo "traversal tests rc=$? at ${SECONDS}s"; tail -n 3 "$OUT/traversal-tests.txt"
tail -n 2 "$OUT"/build-*.log
export PATHBENCH_DATA_DIR=/tmp/pbdata
bash .wt-carry/suite-data/unpack.sh > /dev/null || exit 5
{ nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv; lscpu | grep "Model name"; } | tee "$OUT/machine.txt"
timeout "${BUDGET_S:-300}" bash scripts/device/gpu_variants_ab.sh $c/variants.txt $c/cases.txt /tmp/ab-pairs 2>&1 | tee "$OUT/ab-pairs.txt"
cp /tmp/ab-pairs/variants.tsv "$OUT/ab-pairs.tsv"
echo "done at ${SECONDS}s"
