#!/usr/bin/env bash
# One device call's interleaved A/B of GPU tracer builds made on the development machine
# (the GPU host cannot build in a few minutes, and device time is short). The steps every
# such call repeated, now in one place:
#   1. unpacks each BINARIES/pathbench-NAME.xz, or each pathbench-NAME in
#      BINARIES/binaries.tar.xz (one solid archive: smaller where the builds share code, and
#      a call carries at most 64 MiB), to /tmp/pb/NAME/bin/pathbench, and stops if one of
#      them misses a library;
#   2. sources RUNTIME_LIBS/unpack.sh first: the Debian runtime libraries of a build
#      without MPI, NCCL or OIIO (Embree, TBB, fmt, pugixml, tinyobjloader), unpacked
#      under /opt/rdeps and put on LD_LIBRARY_PATH;
#   3. installs the suite's meshes from SUITE_DATA (scripts/pack-suite-data.sh's folder)
#      into PATHBENCH_DATA_DIR (/tmp/pbdata unless set);
#   4. records the GPU (name, driver, clocks) and the host's CPU in $OUT/machine.txt;
#   5. runs gpu_variants_ab.sh over VARIANTS and CASES (a VARIANTS line names
#      /tmp/pb/NAME), leaving $OUT/ab-LABEL.txt (the table) and $OUT/ab-LABEL.tsv (every
#      round).
#   scripts/device/gpu_binaries_ab.sh BINARIES RUNTIME_LIBS SUITE_DATA VARIANTS CASES LABEL
# A binary for it, on the development machine (sm_90, a build configured with
# -DPATHBENCH_MPI=OFF -DPATHBENCH_NCCL=OFF -DPATHBENCH_OIIO=OFF -DPATHBENCH_TESTS=OFF):
#   strip -o /tmp/pathbench BUILD/bin/pathbench && xz -6 -c /tmp/pathbench > BINARIES/pathbench-NAME.xz
# or, for several, stripped copies named pathbench-NAME in one folder DIR:
#   tar -C DIR -cf - . | xz -9e --lzma2=preset=9e,dict=192MiB > BINARIES/binaries.tar.xz
# BUDGET_S (default 500) bounds the A/B itself, so that what ran comes back inside the
# call's limit.
# Checks of a build before its A/B, so that a call that tests a change needs no script of
# its own:
#   - BINARIES/pathbench_gpu_tests.xz (the GPU test binary, stripped, of the build named
#     first in VARIANTS' tree): run first, whole, into $OUT/gpu-tests-LABEL.txt. Its tests
#     read the tree through the source folder compiled into them, TESTS_SOURCE_DIR (default
#     /work/main), which is linked to this checkout where the GPU host lacks it;
#   - SANITIZE="render arguments": compute-sanitizer memcheck and racecheck of the first
#     unpacked pathbench on that render, into $OUT/sanitizer-LABEL-TOOL.txt.
# Their one-line outcomes lead $OUT/summary-LABEL.txt.
set -uo pipefail
usage="usage: scripts/device/gpu_binaries_ab.sh BINARIES RUNTIME_LIBS SUITE_DATA VARIANTS CASES LABEL"
bins=${1:?$usage}
libs=${2:?$usage}
suite=${3:?$usage}
variants=${4:?$usage}
cases=${5:?$usage}
label=${6:?$usage}
out=${OUT:?gpu_binaries_ab.sh: set OUT to the device call output folder}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

# shellcheck source=/dev/null
source "$libs/unpack.sh"
shopt -s nullglob
rm -rf /tmp/pb-unpacked && mkdir -p /tmp/pb-unpacked
if [ -f "$bins/binaries.tar.xz" ]; then tar -C /tmp/pb-unpacked -xJf "$bins/binaries.tar.xz" || exit 3; fi
for f in "$bins"/pathbench-*.xz; do xz -dc "$f" > "/tmp/pb-unpacked/$(basename "$f" .xz)" || exit 3; done
unpacked=(/tmp/pb-unpacked/pathbench-*)
if [ ${#unpacked[@]} -eq 0 ]; then
  echo "gpu_binaries_ab.sh: no pathbench-NAME.xz or binaries.tar.xz in $bins" >&2
  exit 2
fi
for f in "${unpacked[@]}"; do
  name=${f##*/pathbench-}
  first=${first:-$name}
  mkdir -p "/tmp/pb/$name/bin"
  mv "$f" "/tmp/pb/$name/bin/pathbench" && chmod +x "/tmp/pb/$name/bin/pathbench" || exit 3
  if ldd "/tmp/pb/$name/bin/pathbench" | grep "not found"; then
    echo "gpu_binaries_ab.sh: /tmp/pb/$name/bin/pathbench misses the libraries above" >&2
    exit 4
  fi
done
export PATHBENCH_DATA_DIR=${PATHBENCH_DATA_DIR:-/tmp/pbdata}
bash "$suite/unpack.sh" > /dev/null || exit 5
{
  nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
  lscpu | grep "Model name"
} | tee "$out/machine.txt"
summary="$out/summary-$label.txt"
: > "$summary"
if [ -f "$bins/pathbench_gpu_tests.xz" ]; then
  xz -dc "$bins/pathbench_gpu_tests.xz" > /tmp/pb/pathbench_gpu_tests && chmod +x /tmp/pb/pathbench_gpu_tests || exit 3
  src=${TESTS_SOURCE_DIR:-/work/main}
  if [ ! -e "$src" ]; then mkdir -p "$(dirname "$src")" && ln -s "$(cd "$here/../.." && pwd)" "$src"; fi
  (cd /tmp && timeout "${TESTS_BUDGET_S:-240}" /tmp/pb/pathbench_gpu_tests > "$out/gpu-tests-$label.txt" 2>&1)
  rc=$?
  echo "pathbench_gpu_tests rc=$rc: $(grep -E '^\[  PASSED  \]|^\[  FAILED  \] [0-9]+ test' "$out/gpu-tests-$label.txt" | tr '\n' ' ')" |
    tee -a "$summary"
fi
if [ -n "${SANITIZE:-}" ]; then
  # shellcheck source=scripts/device/sanitizer_run.sh
  source "$here/sanitizer_run.sh"
  for tool in memcheck racecheck; do
    # shellcheck disable=SC2086  # SANITIZE: render arguments, as words
    echo "compute-sanitizer $tool $(sanitizer_run "$out/sanitizer-$label-$tool.txt" "$tool" "/tmp/pb/$first/bin/pathbench" \
      --device gpu --quiet $SANITIZE --out /tmp/pb/sanitized.pfm)" | tee -a "$summary"
  done
fi
timeout "${BUDGET_S:-500}" bash "$here/gpu_variants_ab.sh" "$variants" "$cases" "/tmp/ab-$label" 2>&1 | tee "$out/ab-$label.txt"
cp "/tmp/ab-$label/variants.tsv" "$out/ab-$label.tsv"
echo "gpu_binaries_ab.sh: done at ${SECONDS}s"
