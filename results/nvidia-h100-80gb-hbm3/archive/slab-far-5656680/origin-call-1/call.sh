#!/usr/bin/env bash
# Issue 32, interleaved against HEAD (ff6b3e8: slab_far), three builds made on the GPU host:
# oat = the parked megakernel's binary-BVH leaf test reads the ray's origin from the path
# state in shared memory (OriginInShared), so o is not live through the node loop and ptxas
# keeps o * inv instead of recomputing it at every node (3 FMUL a node: 0 in the SASS);
# full = that and the chunk loop's state in shared memory too (for_each_chunk_parked).
set -u
source .gpu-deps/unpack.sh > /dev/null
export PATH=$PATH:/usr/local/cuda/bin
c=.wt-carry/ab3
rm -rf /tmp/src-head /tmp/src-oat && mkdir -p /tmp/src-head
tar --exclude=./.wt-carry --exclude=./.gpu-deps --exclude=./.git -cf - . | tar -xf - -C /tmp/src-head
cp -r /tmp/src-head /tmp/src-oat
(cd /tmp/src-head && patch -s -R -p1 < "$OLDPWD/$c/new.patch") || { echo "new.patch does not reverse"; exit 1; }
(cd /tmp/src-oat && patch -s -p1 < "$OLDPWD/$c/nochunk.patch") || { echo "nochunk.patch does not apply"; exit 1; }
build() {  # SRC NAME
  cmake -S "$1" -B "/tmp/b-$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
    -DPATHBENCH_MPI=OFF -DPATHBENCH_NCCL=OFF -DPATHBENCH_PYTHON=OFF -DPATHBENCH_TESTS=OFF \
    -DCMAKE_CUDA_ARCHITECTURES=90 > "/tmp/configure-$2.log" 2>&1 &&
  cmake --build "/tmp/b-$2" -j 6 --target pathbench > "/tmp/build-$2.log" 2>&1
  echo "build $2 rc=$? at ${SECONDS}s"; tail -n 1 "/tmp/build-$2.log"
  mkdir -p "/tmp/pb/$2/bin" && cp "/tmp/b-$2/bin/pathbench" "/tmp/pb/$2/bin/"
}
build /tmp/src-head head &
build /tmp/src-oat oat &
build "$PWD" full &
wait
export PATHBENCH_DATA_DIR=/tmp/pbdata
bash .wt-carry/suite-data/unpack.sh > /dev/null || exit 5
{ nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv; lscpu | grep "Model name"; } | tee "$OUT/machine.txt"
timeout "${BUDGET_S:-300}" bash scripts/device/gpu_variants_ab.sh $c/variants.txt $c/cases.txt /tmp/ab-oat 2>&1 | tee "$OUT/ab-oat.txt"
cp /tmp/ab-oat/variants.tsv "$OUT/ab-oat.tsv"
echo "done at ${SECONDS}s"
