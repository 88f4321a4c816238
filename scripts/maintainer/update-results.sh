#!/usr/bin/env bash
# Maintainers only: rewrite the committed results of this machine (results/<machine>/) and
# the README's "results at a glance" table. Nothing else in the project writes tracked files.
#   scripts/maintainer/update-results.sh reproduce [ARGS]   pathbench reproduce --update-committed
#   scripts/maintainer/update-results.sh accuracy [ARGS]    scripts/accuracy.sh --update-committed
#   scripts/maintainer/update-results.sh glance             README's table from results/history
# Review with `git diff` and commit by hand.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
what=${1:?usage: update-results.sh reproduce|accuracy|glance [ARGS]}
shift
case "$what" in
  reproduce) build/bin/pathbench reproduce --update-committed "$@" ;;
  accuracy) scripts/accuracy.sh --update-committed "$@" ;;
  glance) .venv/bin/python scripts/results_glance.py --write README.md ;;
  *) echo "update-results.sh: unknown task '$what' (reproduce, accuracy or glance)" >&2; exit 2 ;;
esac
