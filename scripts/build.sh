#!/usr/bin/env bash
# Configures and builds pathbench into build/ (binaries in build/bin/).
# Extra arguments go to the CMake configure step, e.g. -DPATHBENCH_CUDA=OFF.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build --parallel "$(nproc)"
