#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the 2015
# paper's experiment on the CPU (and the GPU where there is one), printing the table.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
scripts/install-deps.sh
scripts/build.sh
build/bin/pathbench reproduce "$@"
