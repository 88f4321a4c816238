#!/usr/bin/env bash
# Issue 35, device call 1 (the GPU host's Xeon; no perf there): the stage profile of the
# batched CPU strategies (a PATHBENCH_STAGE_TIMERS build), main's times interleaved with it
# (the timers' own cost), and Embree's raw packet rates for the ray mix. Binaries built on the
# development VM (baseline x86-64, run-time ISA dispatch), their libraries beside them in
# $C/lib. Usage, from the repository root there: C=<carry dir> scripts/device/cpu_profile_xeon.sh
set -u
C=${C:?carry dir}
mkdir -p /tmp/cpu35lib && tar -xJf $C/lib.tar.xz -C /tmp/cpu35lib && export LD_LIBRARY_PATH=/tmp/cpu35lib/lib
B=$C/bin
{ lscpu; echo; nproc; uptime; } > "$OUT/host.txt"
grep -o 'avx512[a-z_0-9]*' /proc/cpuinfo | sort -u | tr '\n' ' ' >> "$OUT/host.txt"
uptime
ab=$C/cpu_ab.py
# Stage profile, all threads, full frame: 3 rounds each strategy (+ main interleaved).
python3 $ab --bin main=$B/pathbench-main --bin st=$B/pathbench-st --rounds 3 --stderr-to "$OUT/stages.txt" \
  --out "$OUT/ab-main-st.json" 2>&1 | tee "$OUT/ab-main-st.txt"
# One thread, 256x256x50 (no idle threads, no tail): where a core's time goes.
python3 $ab --bin st=$B/pathbench-st --rounds 1 --spp 50 --threads 1 --stderr-to "$OUT/stages-1t.txt" \
  --out /tmp/ab-1t.json 2>&1 | tail -3
# Pixel tiles of 8 instead of 16 (the tail at the end of the frame), profile build only.
PB_PIXEL_TILE=8 python3 $ab --bin st8=$B/pathbench-st --strategies pixel --rounds 2 --stderr-to "$OUT/stages-tile8.txt" \
  --out /tmp/ab-t8.json 2>&1 | tail -2
# Embree's raw rates (pathbench-bench raycast, the same robust scene) for the ray mix.
PYTHONPATH=tools python3 -c "
import json, raw_embree_mix as r
ctx = {}
rates = r.measure('$B/pathbench-bench', context=ctx)
json.dump({'rates': rates, 'embree': (ctx.get('fingerprint') or {}).get('embree')}, open('$OUT/raw.json', 'w'), indent=1)
print(rates)"
uptime
