#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs every CTest suite
# (CPU tests; GPU tests report SKIPPED without a GPU) and the Python tests, then the
# sanitizer job (scripts/sanitize.sh: unit and CLI tests under ASan + UBSan) and a short
# fuzz run (scripts/fuzz.sh all 180: three minutes over the six fuzz targets).
# Skip those two locally with PATHBENCH_SKIP_SANITIZE=1 and PATHBENCH_SKIP_FUZZ=1;
# PATHBENCH_FUZZ_SECONDS sets the fuzz time.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
scripts/install-deps.sh
scripts/build.sh "$@"
ctest --test-dir build --output-on-failure --timeout 1800 -j "$(nproc)"
if compgen -G "tests/python/test_*.py" >/dev/null; then
  # PATHBENCH_SLOW=1: also `pip install .` into a fresh venv once (a full build of the module, minutes)
  PATHBENCH_SLOW=1 .venv/bin/python -m pytest -q tests/python
fi
if [ "${PATHBENCH_SKIP_SANITIZE:-0}" != 1 ]; then
  scripts/sanitize.sh
fi
if [ "${PATHBENCH_SKIP_FUZZ:-0}" != 1 ]; then
  scripts/fuzz.sh all "${PATHBENCH_FUZZ_SECONDS:-180}"
fi
