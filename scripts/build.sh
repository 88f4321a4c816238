#!/usr/bin/env bash
# Configures and builds pathbench into build/ (binaries in build/bin/).
# Extra arguments go to the CMake configure step, e.g. -DPATHBENCH_CUDA=OFF.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
# ccache (installed by install-deps.sh) makes rebuilds and CI re-runs cheap. base_dir is the
# checkout, so clones and worktrees in other folders share the cache.
launcher=()
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=1
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_CUDA_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "$@"
cmake --build build --parallel "$(nproc)"
