#!/usr/bin/env bash
# Issue 32, interleaved against HEAD (ff6b3e8: slab_far), three builds made on the GPU host:
# chunk = the parked megakernel's chunk loop state in shared memory (for_each_chunk_parked);
# oat2 = that and the binary-BVH leaf test reading the ray's origin from the parked path state
# (OriginInShared) through a plain ld.shared whose address depends on the leaf (the volatile
# form of ab3 put YIELDs in the walks and was 1.56x slower), so o is not live through the node
# loop (0 FMUL a node in the SASS, 3 before).
set -u
source .gpu-deps/unpack.sh > /dev/null
export PATH=$PATH:/usr/local/cuda/bin
c=.wt-carry/ab4
rm -rf /tmp/src-head /tmp/src-chunk && mkdir -p /tmp/src-head
tar --exclude=./.wt-carry --exclude=./.gpu-deps --exclude=./.git -cf - . | tar -xf - -C /tmp/src-head
(cd /tmp/src-head && patch -s -R -p1 < "$OLDPWD/$c/new.patch") || { echo "new.patch does not reverse"; exit 1; }
cp -r /tmp/src-head /tmp/src-chunk
(cd /tmp/src-chunk && patch -s -p1 < "$OLDPWD/$c/chunk.patch") || { echo "chunk.patch does not apply"; exit 1; }
build() {  # SRC NAME
  cmake -S "$1" -B "/tmp/b-$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
    -DPATHBENCH_MPI=OFF -DPATHBENCH_NCCL=OFF -DPATHBENCH_PYTHON=OFF -DPATHBENCH_TESTS=OFF \
    -DCMAKE_CUDA_ARCHITECTURES=90 > "/tmp/configure-$2.log" 2>&1 &&
  cmake --build "/tmp/b-$2" -j 6 --target pathbench > "/tmp/build-$2.log" 2>&1
  echo "build $2 rc=$? at ${SECONDS}s"; tail -n 1 "/tmp/build-$2.log"
  mkdir -p "/tmp/pb/$2/bin" && cp "/tmp/b-$2/bin/pathbench" "/tmp/pb/$2/bin/"
}
build /tmp/src-head head &
build /tmp/src-chunk chunk &
build "$PWD" oat2 &
wait
export PATHBENCH_DATA_DIR=/tmp/pbdata
bash .wt-carry/suite-data/unpack.sh > /dev/null || exit 5
{ nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv; lscpu | grep "Model name"; } | tee "$OUT/machine.txt"
timeout "${BUDGET_S:-300}" bash scripts/device/gpu_variants_ab.sh $c/variants.txt $c/cases.txt /tmp/ab-oat2 2>&1 | tee "$OUT/ab-oat2.txt"
cp /tmp/ab-oat2/variants.tsv "$OUT/ab-oat2.tsv"
echo "done at ${SECONDS}s"
