#!/usr/bin/env python3
"""The hybrid CPU+GPU render against one GPU, from scripts/mpi_device_check.sh's `hybrid`
phase: interleaved rounds of report JSONs (gpu-<size>-<i>.json, hy-<size>-<i>.json).

Both are timed from the frame's start to the film on the host: one GPU's `seconds` (host
clock around the frame, after its warm-up) plus `film_download_seconds`, against the
hybrid's `ranks.frame_seconds` (common start of the ranks to the film reduced on rank 0).
Prints a Markdown table with medians, the ratio and an exact two-sided Mann-Whitney U
test (standard library only: the GPU host has no SciPy).

    python3 tools/hybrid_timing.py DIR
"""
import itertools
import json
import statistics
import sys
from pathlib import Path


def u_test(a, b):
    """Exact two-sided Mann-Whitney U p-value (no ties expected in timings)."""
    def u_of(x, y):
        return sum((xi > yj) + 0.5 * (xi == yj) for xi in x for yj in y)
    u = u_of(a, b)
    pooled = list(a) + list(b)
    n = len(a)
    mean = len(a) * len(b) / 2
    extreme = total = 0
    for idx in itertools.combinations(range(len(pooled)), n):
        chosen = set(idx)
        x = [pooled[i] for i in idx]
        y = [pooled[i] for i in range(len(pooled)) if i not in chosen]
        total += 1
        extreme += abs(u_of(x, y) - mean) >= abs(u - mean) - 1e-9
    return u, extreme / total


def main(folder):
    d = Path(folder)
    sizes = sorted({p.name.split("-")[1] for p in d.glob("gpu-*.json")}, key=int)
    print("| frame | one GPU (s, median) | GPU device_seconds | hybrid (s, median) | hybrid / GPU | "
          "CPU share | reduce (s) | U test p | rounds |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for size in sizes:
        gpu, dev, hy, share, red = [], [], [], [], []
        frame = ""
        for p in sorted(d.glob(f"gpu-{size}-*.json")):
            g = json.loads(p.read_text())
            frame = f"{g['width']}x{g['height']}x{g['spp']}"
            gpu.append(g["seconds"] + g.get("film_download_seconds", 0.0))
            dev.append(g["device_seconds"])
        for p in sorted(d.glob(f"hy-{size}-*.json")):
            h = json.loads(p.read_text())
            r = h["ranks"]
            hy.append(r["frame_seconds"])
            share.append(r["device_share"].get("cpu", 0.0))
            red.append(r["reduce_seconds"])
        if not gpu or not hy:
            continue
        _, p = u_test(gpu, hy)
        mg, mh = statistics.median(gpu), statistics.median(hy)
        print(f"| {frame} | {mg:.4f} | {statistics.median(dev):.4f} | {mh:.4f} | {mh / mg:.3f} | "
              f"{100 * statistics.median(share):.2f} % | {statistics.median(red):.4f} | {p:.3f} | "
              f"{len(gpu)} + {len(hy)} |")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
