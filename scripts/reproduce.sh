#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the 2015
# paper's experiment on the CPU (and the GPU where there is one), printing the table.
# Writes into pathbench-out/<machine>/ (git-ignored) unless --out-dir names a folder; it
# never touches tracked files (the committed results/ are updated by
# scripts/maintainer/update-results.sh). Extra arguments go to `pathbench reproduce`.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
scripts/install-deps.sh
scripts/build.sh
build/bin/pathbench reproduce "$@"
