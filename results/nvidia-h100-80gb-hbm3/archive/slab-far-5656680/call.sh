#!/usr/bin/env bash
# Issue 32, interleaved against main's GPU code (5656680): the slab test's far end widened by 6
# ulps and clamped to t in one DPX instruction (slab_far: __viaddmin_s32), where the product by
# 1 + 2 gamma(3) and the clamp took two; ao: that and the any-hit walks in the builder's child order
# (no sort by entry distance). Both builds made on the GPU host (pathbench only).
set -u
source .gpu-deps/unpack.sh > /dev/null
export PATH=$PATH:/usr/local/cuda/bin
c=.wt-carry/ab1
rm -rf /tmp/src-base && mkdir -p /tmp/src-base
tar --exclude=./.wt-carry --exclude=./.gpu-deps --exclude=./.git -cf - . | tar -xf - -C /tmp/src-base
(cd /tmp/src-base && patch -s -R -p1 < "$OLDPWD/$c/new.patch") || { echo "the patch does not reverse"; exit 1; }
rm -rf /tmp/src-ao && cp -r /tmp/src-base /tmp/src-ao
(cd /tmp/src-ao && patch -s -p1 < "$OLDPWD/$c/new.patch" && patch -s -p1 < "$OLDPWD/$c/anyorder.patch") || { echo "anyorder does not apply"; exit 1; }
build() {  # SRC NAME
  cmake -S "$1" -B "/tmp/b-$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
    -DPATHBENCH_MPI=OFF -DPATHBENCH_NCCL=OFF -DPATHBENCH_PYTHON=OFF -DPATHBENCH_TESTS=OFF \
    -DCMAKE_CUDA_ARCHITECTURES=90 > "$OUT/configure-$2.log" 2>&1 &&
  cmake --build "/tmp/b-$2" -j 6 --target pathbench > "$OUT/build-$2.log" 2>&1
  echo "build $2 rc=$? at ${SECONDS}s"
  mkdir -p "/tmp/pb/$2/bin" && cp "/tmp/b-$2/bin/pathbench" "/tmp/pb/$2/bin/"
}
build /tmp/src-base base &
build "$PWD" far &
build /tmp/src-ao ao &
wait
tail -3 "$OUT"/build-*.log
export PATHBENCH_DATA_DIR=/tmp/pbdata
bash .wt-carry/suite-data/unpack.sh > /dev/null || exit 5
{ nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv; lscpu | grep "Model name"; } | tee "$OUT/machine.txt"
timeout "${BUDGET_S:-300}" bash scripts/device/gpu_variants_ab.sh $c/variants.txt $c/cases.txt /tmp/ab-far 2>&1 | tee "$OUT/ab-far.txt"
cp /tmp/ab-far/variants.tsv "$OUT/ab-far.tsv"
echo "done at ${SECONDS}s"
