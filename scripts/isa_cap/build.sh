#!/usr/bin/env bash
# Builds the Embree ISA-cap shim (embree_isa_cap.c: why it exists, and its environment).
#   scripts/isa_cap/build.sh [OUT.so]     default: build/isa_cap/libembree_isa_cap.so
# Needs only a C compiler (no Embree headers). Use it as
#   LD_PRELOAD=OUT.so PATHBENCH_EMBREE_MAX_ISA=avx2 COMMAND ...
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
out=${1:-$here/../../build/isa_cap/libembree_isa_cap.so}
mkdir -p "$(dirname "$out")"
${CC:-cc} -O2 -Wall -Wextra -shared -fPIC -o "$out" "$here/embree_isa_cap.c" -ldl -lpthread
echo "$(cd "$(dirname "$out")" && pwd)/$(basename "$out")"
