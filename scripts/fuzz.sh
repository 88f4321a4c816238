#!/usr/bin/env bash
# Runs one libFuzzer target for a bounded time and fails on any finding: a crash, a
# sanitizer report (ASan + UBSan), a leak, a slow input (> 10 s) or one over 2 GB.
#   scripts/fuzz.sh TARGET SECONDS     TARGET: scene_json | obj | bench_json | ply | gltf | mitsuba | off | compare_context | history | all
# (history: the Python history's readers, tests/fuzz/python/fuzz_history.py under atheris)
# Builds build-fuzz/ with clang first (-DPATHBENCH_FUZZ=ON). The seed corpus is
# tests/fuzz/corpus/TARGET (read only); what the fuzzer learns goes to
# build-fuzz/corpus/TARGET and is kept between runs; a failing input is written to
# build-fuzz/artifacts/TARGET/ (add it to tests/fuzz/regressions/TARGET/ with the fix).
# "all" splits SECONDS between the targets. Extra libFuzzer flags: FUZZ_FLAGS.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
targets="scene_json obj bench_json ply gltf mitsuba off compare_context history"
target=${1:?usage: scripts/fuzz.sh scene_json|obj|bench_json|ply|gltf|mitsuba|off|compare_context|history|all SECONDS}
seconds=${2:?usage: scripts/fuzz.sh TARGET SECONDS}
build=${PATHBENCH_FUZZ_BUILD:-build-fuzz}

if [ "$target" = all ]; then
  count=$(echo $targets | wc -w)
  each=$(( seconds / count > 0 ? seconds / count : 1 ))
  for t in $targets; do "$0" "$t" "$each"; done
  exit 0
fi
if [ "$target" = history ]; then  # Python, no build: atheris, else a seeded mutation loop
  py=${PATHBENCH_PYTHON:-.venv/bin/python}
  mkdir -p "$build/corpus/history" "$build/artifacts/history"
  echo "[fuzz] history for $seconds s"
  if ! "$py" -c "import atheris" 2>/dev/null; then
    echo "[fuzz] history: atheris not installed (tools/requirements.txt): seeded mutation instead"
    exec "$py" tests/fuzz/python/fuzz_history.py --mutate "$seconds" tests/fuzz/corpus/history
  fi
  # shellcheck disable=SC2086
  "$py" tests/fuzz/python/fuzz_history.py "$build/corpus/history" tests/fuzz/corpus/history \
    -dict=tests/fuzz/history.dict -max_total_time="$seconds" -max_len=65536 -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/artifacts/history/" ${FUZZ_FLAGS:-} 2>&1 | tail -n 40
  exit 0
fi
case "$target" in
  scene_json|bench_json|compare_context) dict=tests/fuzz/json.dict ;;
  gltf) dict=tests/fuzz/gltf.dict ;;
  obj) dict=tests/fuzz/obj.dict ;;
  ply) dict=tests/fuzz/ply.dict ;;
  off) dict=tests/fuzz/off.dict ;;
  mitsuba) dict=tests/fuzz/xml.dict ;;
  *) echo "fuzz.sh: unknown target '$target' ($targets or all)" >&2; exit 2 ;;
esac

if [ ! -x "$build/bin/fuzz_$target" ] || [ "${FUZZ_REBUILD:-1}" = 1 ]; then
  CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPATHBENCH_FUZZ=ON \
    -DPATHBENCH_CUDA=OFF -DPATHBENCH_PYTHON=OFF -DPATHBENCH_OIIO=OFF >/dev/null
  cmake --build "$build" --target "fuzz_$target" -j "$(nproc)" >/dev/null
fi
mkdir -p "$build/corpus/$target" "$build/artifacts/$target"
# -rss_limit_mb / -malloc_limit_mb: an input that needs more than 2 GB is a finding;
# -timeout: so is one that takes over 10 s. Leaks are reported (detect_leaks) too.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
echo "[fuzz] $target for $seconds s"
# shellcheck disable=SC2086
"$build/bin/fuzz_$target" "$build/corpus/$target" "tests/fuzz/corpus/$target" \
  -dict="$dict" -max_total_time="$seconds" -max_len=65536 -timeout=10 \
  -rss_limit_mb=2048 -malloc_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$build/artifacts/$target/" ${FUZZ_FLAGS:-} 2>&1 | tail -n 40
