#!/usr/bin/env bash
# An interleaved A/B of GPU trees built on the GPU host itself (pathbench only, several
# trees at once: 3-4 minutes on its 16 cores): each TREE is this working tree, or a copy of it
# with a patch reversed (a base); then scripts/device/gpu_variants_ab.sh runs VARIANTS (whose
# build directories are /tmp/pb/NAME) over CASES, for at most BUDGET_S seconds (default 300).
#   scripts/device/gpu_trees_ab.sh OUT_DIR VARIANTS CASES NAME[:PATCH] ...
# NAME alone: this tree; NAME:PATCH: this tree with PATCH (`git diff BASE` made on the
# development host) reversed. Writes to OUT_DIR the builds' and configures' logs, machine.txt,
# ab.txt (the comparison) and ab.tsv (every render). Needs .gpu-deps (../shared/gpu-host/README.md);
# the suite's meshes from .wt-carry/suite-data (scripts/pack-suite-data.sh) where present.
set -uo pipefail
usage="usage: scripts/device/gpu_trees_ab.sh OUT_DIR VARIANTS CASES NAME[:PATCH] ..."
out=${1:?$usage}; variants=${2:?$usage}; cases=${3:?$usage}
shift 3
[ $# -gt 0 ] || { echo "gpu_trees_ab.sh: no tree named" >&2; exit 2; }
inputs=("$variants" "$cases")
for t in "$@"; do [ "${t#*:}" != "$t" ] && inputs+=("${t#*:}"); done
for f in "${inputs[@]}"; do
  if [ ! -f "$f" ] || [ ! -r "$f" ]; then echo "gpu_trees_ab.sh: $f: not a readable file" >&2; exit 2; fi
done  # before anything is built
variants=$(realpath "$variants"); cases=$(realpath "$cases")
mkdir -p "$out" && out=$(realpath "$out")
cd "$(dirname "${BASH_SOURCE[0]}")/../.." || exit 1
# shellcheck disable=SC1091  # made on the development host (../shared/gpu-host/README.md)
if [ -f .gpu-deps/unpack.sh ]; then source .gpu-deps/unpack.sh > /dev/null; fi
export PATH=$PATH:/usr/local/cuda/bin
jobs=$(( $(nproc) / $# )); [ "$jobs" -ge 2 ] || jobs=2
build() {  # NAME SOURCE
  cmake -S "$2" -B "/tmp/b-$1" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPATHBENCH_CUDA=ON -DPATHBENCH_OIIO=OFF \
    -DPATHBENCH_MPI=OFF -DPATHBENCH_NCCL=OFF -DPATHBENCH_PYTHON=OFF -DPATHBENCH_TESTS=OFF \
    -DCMAKE_CUDA_ARCHITECTURES=90 > "$out/configure-$1.log" 2>&1 &&
    cmake --build "/tmp/b-$1" -j "$jobs" --target pathbench > "$out/build-$1.log" 2>&1
  local rc=$?
  echo "build $1 rc=$rc at ${SECONDS}s"
  [ $rc = 0 ] && mkdir -p "/tmp/pb/$1/bin" && cp "/tmp/b-$1/bin/pathbench" "/tmp/pb/$1/bin/"
}
for tree in "$@"; do
  name=${tree%%:*}
  if [ "$name" = "$tree" ]; then build "$name" "$PWD" & continue; fi
  patch_file=$(realpath "${tree#*:}")
  src=/tmp/src-$name
  rm -rf "$src" && mkdir -p "$src"
  tar --exclude=./.wt-carry --exclude=./.gpu-deps --exclude=./.git --exclude='./build*' -cf - . | tar -xf - -C "$src"
  (cd "$src" && patch -s -R -p1 < "$patch_file") || { echo "$patch_file does not reverse on this tree"; exit 1; }
  build "$name" "$src" &
done
wait
if [ -f .wt-carry/suite-data/unpack.sh ]; then
  export PATHBENCH_DATA_DIR=/tmp/pbdata
  bash .wt-carry/suite-data/unpack.sh > /dev/null || { echo "the suite's meshes do not unpack"; exit 5; }
fi
{ nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv; lscpu | grep "Model name"; } \
  | tee "$out/machine.txt"
timeout "${BUDGET_S:-300}" bash scripts/device/gpu_variants_ab.sh "$variants" "$cases" /tmp/ab-trees 2>&1 | tee "$out/ab.txt"
cp /tmp/ab-trees/variants.tsv "$out/ab.tsv"
echo "done at ${SECONDS}s"
