#!/usr/bin/env bash
# The sanitizer job: the unit and CLI tests under AddressSanitizer + UndefinedBehavior-
# Sanitizer (any report fails the test), in build-asan/ (CUDA and Python off; GPU
# tests do not apply). scripts/test.sh runs it after the ordinary tests unless
# PATHBENCH_SKIP_SANITIZE=1. Left out (too slow under ASan, and they test numbers, not
# memory): the unit_slow label (statistical and reference renders) and the benchmark
# smoke runs (bench.*), json.strict_outputs (it runs pathbench-bench, which this build
# leaves out, and checks JSON, not memory) and cli.peak_memory (it compares the report's
# peak with the process's maximum RSS, which ASan's shadow memory and exit-time leak check
# change). Extra arguments go to the CMake configure step.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
start=$SECONDS
# -O1 -g1: less compile time than -O2 -g (CI has 2 cores), and still file:line in reports.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DPATHBENCH_SANITIZE=ON \
  -DPATHBENCH_CUDA=OFF -DPATHBENCH_PYTHON=OFF -DPATHBENCH_MPI=OFF "$@" >/dev/null
# (PATHBENCH_MPI=OFF: the mpi label is not run here, OpenMPI's own allocations would read
# as leaks; the unit and CLI tests run the one-rank world, run/src/single_world.cpp.)
cmake --build build-asan --parallel "$(nproc)" --target pathbench pathbench_unit_tests pathbench_bench_tests \
  pathbench_traversal_tests pathbench_host_tracer_tests fuzz_scene_json_replay fuzz_obj_replay fuzz_bench_json_replay fuzz_ply_replay \
  fuzz_gltf_replay fuzz_mitsuba_replay fuzz_compare_context_replay fuzz_off_replay
# Leaks are errors; TBB's and Embree's process-lifetime allocations are not ours.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/tests/sanitizer/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir build-asan --output-on-failure --timeout 900 -j "$(nproc)" -L "^(unit|cli)$" \
  -E "^(bench\.|json\.strict_outputs$|cli\.peak_memory$)"
echo "[sanitize] ASan + UBSan tests passed in $(( (SECONDS - start) / 60 )) min $(( (SECONDS - start) % 60 )) s"
