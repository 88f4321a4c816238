#!/usr/bin/env bash
# Issue 35, device call 2 (the GPU host's Xeon, no network): tools/mitsuba_speed.py for this
# branch with main's build as --baseline (interleaved, >= 5 rounds, >= 10 Mitsuba renders), then
# --isa avx2 of both builds interleaved (scripts/device/cpu_ab.py). Carried in $C: the two
# pathbench builds (bin/, made on the development VM: baseline x86-64, run-time ISA dispatch),
# their libraries (lib.tar.xz), Mitsuba 3.9.1 + Dr.Jit 1.5.0 from their cp312 wheels cut to
# llvm_ad_rgb and the plugins paper-cornell needs (mitsuba.tar.xz) and Debian's libLLVM 19
# (libLLVM.xz) with what it links that the host may lack (llvmdeps.tar.xz: libffi 8, libtinfo 6,
# libzstd 1 from Debian 12, and stubs of libz3 4, libedit 2 and libxml2 2 defining the functions
# libLLVM imports from them as abort(): the JIT never calls them, the loader only needs them
# bound), each used only where `ldconfig -p` does not list it. Run from the repository root there (main's tree): C=<carry dir> <this script>.
set -u
C=${C:?carry dir}
T=/tmp/cpu35
mkdir -p $T/lib $T/mi $T/bin
tar -xJf $C/lib.tar.xz -C $T/lib
tar -xJf $C/mitsuba.tar.xz -C $T/mi
xz -dc $C/libLLVM.xz > $T/libLLVM.so.19.1
mkdir -p $T/llvmdeps.all $T/llvmdeps
tar -xJf $C/llvmdeps.tar.xz -C $T/llvmdeps.all
for f in $T/llvmdeps.all/*; do
  n=$(basename $f)
  ldconfig -p | grep -q "^[[:space:]]*$n " || cp $f $T/llvmdeps/
done
echo "libLLVM's libraries taken from the carry: $(ls $T/llvmdeps | tr '\n' ' ')"
builds=$(cd $C/bin && ls pathbench-*.xz | sed 's/pathbench-//; s/\.xz$//')
for b in $builds; do
  xz -dc $C/bin/pathbench-$b.xz > $T/bin/pathbench-$b.real && chmod +x $T/bin/pathbench-$b.real
  # Only pathbench sees these libraries (Mitsuba runs in the tool's own process, with its own Embree).
  printf '#!/bin/sh\nLD_LIBRARY_PATH=%s exec %s "$@"\n' $T/lib $T/bin/pathbench-$b.real > $T/bin/pathbench-$b
  chmod +x $T/bin/pathbench-$b
done
{ lscpu; echo; grep -o 'avx512[a-z_0-9]*' /proc/cpuinfo | sort -u | tr '\n' ' '; echo; uptime; } > "$OUT/host2.txt"
# The host has no pathbench Python module, which the tool's Mitsuba export needs: $C/pymod, where
# carried, holds a stand-in `pathbench` package whose export_mitsuba copies an export made on the
# development host by the real module (pathbench.export_mitsuba(load_scene("paper-cornell"), dir,
# 256, 256, bounces=2)) into the tool's folder.
export PYTHONPATH=$T/mi${C:+$([ -d $C/pymod ] && echo :$C/pymod)} DRJIT_LIBLLVM_PATH=$T/libLLVM.so.19.1 PYTHONUNBUFFERED=1
export LD_LIBRARY_PATH=$T/llvmdeps  # Mitsuba's process: none of these is an Embree
python3 -c "import mitsuba as mi; mi.set_variant('llvm_ad_rgb'); print('mitsuba', mi.__version__)" || exit 3
# main's build as --baseline where it was carried (the carry limit may leave it out: then the
# --isa avx2 runs are specs of this run, against the same Mitsuba renders).
base=() avx2=
if [ -x $T/bin/pathbench-main ]; then base=(--baseline $T/bin/pathbench-main); else avx2=,pixel/isa=avx2,wavefront/isa=avx2; fi
python3 tools/mitsuba_speed.py --pathbench $T/bin/pathbench-new "${base[@]}" \
  --strategies pixel,wavefront,wavefront/paths-in-flight=16384$avx2 --rounds 5 --no-raw --no-history \
  --out-dir "$OUT/ms" 2>&1 | tee "$OUT/mitsuba_speed.log" | grep -v "^mitsuba llvm_ad_rgb: render"
[ -x $T/bin/pathbench-main ] && python3 $C/cpu_ab.py --bin main=$T/bin/pathbench-main --bin new=$T/bin/pathbench-new --isa avx2 --rounds 3 \
  --out "$OUT/ab-avx2.json" 2>&1 | tail -3
uptime
