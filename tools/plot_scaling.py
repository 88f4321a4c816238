#!/usr/bin/env python3
"""Scaling study plots from pathbench-bench JSON (the `scaling` preset).

Regenerate everything (benchmark run + plots) with one command, from the repo root:

    .venv/bin/python tools/plot_scaling.py --run build/bin/pathbench-bench

That runs `pathbench-bench --preset scaling` into results/<machine>/bench-scaling.json
and writes, next to it:

    scaling-rays-vs-triangles.png   rays/s vs triangle count (scaling:N scenes), per
                                    device/strategy, with Embree's raw ray-cast rates
    scaling-time-vs-spp.png         render time vs samples per pixel (paper-cornell 128x128)
    scaling-time-vs-resolution.png  render time vs pixels (paper-cornell, 16 spp)
    scaling-memory.png              memory vs pixels x spp for pixel, wavefront, paper-queue

To plot existing runs (e.g. add a GPU machine's JSON to the CPU one):

    .venv/bin/python tools/plot_scaling.py results/<machine>/bench-scaling.json [more.json ...] \
        [--out-dir results/<machine>]

Set PATHBENCH_SCALING_MAX=1000000 to stop the triangle sweep at 10^6.
"""
import argparse
import json
import os
import re
import subprocess
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

RENDER_RE = re.compile(r"^render/(?P<device>[^/]+)/(?P<strategy>[^/]+)/(?P<scene>[^/]+)/(?P<w>\d+)x(?P<h>\d+)"
                       r"/spp:(?P<spp>\d+)/bounces:(?P<bounces>[^/]+)/(?P<sampling>[^/]+)")
RAYCAST_RE = re.compile(r"^raycast/(?P<device>[^/]+)/(?P<api>[^/]+)/(?P<coherence>[^/]+)/(?P<scene>[^/]+)")
TIME_SCALE = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def load_rows(paths):
    """Median over repetitions of each benchmark, parsed from its name."""
    renders, raycasts, contexts = [], [], []
    for path in paths:
        with open(path) as f:
            doc = json.load(f)
        contexts.append(doc.get("context", {}))
        runs = defaultdict(list)
        for b in doc.get("benchmarks", []):
            if b.get("run_type", "iteration") != "iteration" or b.get("error_occurred"):
                continue
            runs[b.get("run_name", b["name"])].append(b)
        for name, reps in runs.items():
            def med(key):
                vals = sorted(r[key] for r in reps if key in r)
                return vals[len(vals) // 2] if vals else None
            seconds = med("real_time") * TIME_SCALE[reps[0].get("time_unit", "ns")]
            m = RENDER_RE.match(name)
            if m:
                d = m.groupdict()
                row = dict(device=d["device"], strategy=d["strategy"], scene=d["scene"], w=int(d["w"]),
                           h=int(d["h"]), spp=int(d["spp"]), sampling=d["sampling"], seconds=seconds)
                for k in ("rays_per_second", "paths_per_second", "peak_host_bytes", "tracer_host_bytes",
                          "peak_device_bytes", "queue_bytes", "triangles", "pixels_x_spp"):
                    row[k] = med(k)
                renders.append(row)
                continue
            m = RAYCAST_RE.match(name)
            if m:
                d = m.groupdict()
                raycasts.append(dict(device=d["device"], api=d["api"], coherence=d["coherence"], scene=d["scene"],
                                     rays_per_second=med("rays_per_second"), triangles=med("triangles")))
    return renders, raycasts, contexts


def style(device):
    return "-" if device == "cpu" else "--"


def by_series(rows, key):
    """Rows grouped by (device, strategy), each group sorted by key."""
    groups = defaultdict(list)
    for r in rows:
        groups[(r["device"], r["strategy"])].append(r)
    return [(dev, strat, sorted(g, key=key)) for (dev, strat), g in sorted(groups.items())]


def finish(fig, ax, xlabel, ylabel, title, out, legend_size=8):
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=legend_size)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    print("wrote", out)


def plot_rays_vs_triangles(renders, raycasts, out, title):
    rows = [r for r in renders if r["scene"].startswith("scaling:")]
    if not rows:
        print("no scaling:N render rows; skipping", out)
        return
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for dev, strat, g in by_series(rows, lambda r: r["triangles"]):
        ax.plot([r["triangles"] for r in g], [r["rays_per_second"] for r in g], style(dev), marker="o",
                label=f"path tracer: {dev} {strat}")
    rc = [r for r in raycasts if r["scene"].startswith("scaling:")]
    rgroups = defaultdict(list)
    for r in rc:
        if r["api"] in ("intersect1", "intersect16", "occluded16"):
            rgroups[(r["device"], r["api"], r["coherence"])].append(r)
    for (dev, api, coh), g in sorted(rgroups.items()):
        g.sort(key=lambda r: r["triangles"])
        ax.plot([r["triangles"] for r in g], [r["rays_per_second"] for r in g], ":", marker=".", alpha=0.8,
                label=f"raw ray cast: {dev} {api} {coh}")
    sizes = sorted({f"{r['w']}x{r['h']}" for r in rows})
    finish(fig, ax, "triangles", "rays per second",
           f"{title}\nrays/s vs scene size (scaling:N, nee, 2 bounces, {', '.join(sizes)}, 8 spp)", out, 7)


def plot_time_sweep(renders, out, title, key, xlabel, select):
    rows = [r for r in renders if r["scene"] == "paper-cornell" and select(r)]
    if not rows:
        print("no rows; skipping", out)
        return
    fig, ax = plt.subplots(figsize=(7, 5))
    for dev, strat, g in by_series(rows, key):
        ax.plot([key(r) for r in g], [r["seconds"] for r in g], style(dev), marker="o", label=f"{dev} {strat}")
    finish(fig, ax, xlabel, "render time (s)", title, out)


def plot_memory(renders, out, title):
    rows = [r for r in renders if r["scene"] == "paper-cornell"]
    if not rows:
        print("no rows; skipping", out)
        return
    fig, ax = plt.subplots(figsize=(8, 5.5))
    sweeps = [("spp sweep, 128x128", "o", lambda r: r["w"] == 128 and r["h"] == 128),
              ("resolution sweep, 16 spp", "s", lambda r: r["spp"] == 16)]
    for sweep, marker, select in sweeps:
        for dev, strat, g in by_series([r for r in rows if select(r)], lambda r: r["pixels_x_spp"]):
            xs = [r["pixels_x_spp"] for r in g]
            if dev == "cpu":
                ax.plot(xs, [r["tracer_host_bytes"] for r in g], "-", marker=marker,
                        label=f"{dev} {strat}, {sweep}: film + pool + BVH")
            else:
                ax.plot(xs, [r["peak_device_bytes"] for r in g], "--", marker=marker,
                        label=f"{dev} {strat}, {sweep}: device peak")
    for dev, strat, g in by_series(rows, lambda r: r["pixels_x_spp"]):
        if strat != "pixel":
            ax.plot([r["pixels_x_spp"] for r in g], [r["queue_bytes"] for r in g], ":", marker="x",
                    label=f"{dev} {strat}: path pool / queue alone")
        if dev == "cpu" and strat == "pixel":
            ax.plot([r["pixels_x_spp"] for r in g], [r["peak_host_bytes"] for r in g], ":", color="grey",
                    label="cpu: process peak RSS (program + scene + tracer)")
    # The paper's queue: one 48-byte task per sample of the frame.
    lo = min(r["pixels_x_spp"] for r in rows)
    hi = max(r["pixels_x_spp"] for r in rows)
    ax.plot([lo, hi], [48 * lo, 48 * hi], "k--", alpha=0.5, label="paper's queue: 48 B x pixels x spp")
    finish(fig, ax, "pixels x spp", "bytes", title, out, 7)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("json", nargs="*", help="pathbench-bench JSON files (scaling preset)")
    ap.add_argument("--run", metavar="PATHBENCH_BENCH", help="run --preset scaling with this binary first")
    ap.add_argument("--out-dir", help="where the plots go (default: results/<machine> of the first JSON)")
    a = ap.parse_args()
    paths = list(a.json)
    if a.run:
        # Runs into a temporary file, then files it under results/<machine>/ as named
        # by the run's own context.
        os.makedirs("results", exist_ok=True)
        tmp = os.path.join("results", ".bench-scaling.tmp.json")
        cmd = [a.run, "--preset", "scaling", f"--benchmark_out={tmp}", "--benchmark_out_format=json"]
        print(" ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
        with open(tmp) as f:
            slug = json.load(f)["context"].get("machine", "unknown-machine")
        out_dir = a.out_dir or os.path.join("results", slug)
        os.makedirs(out_dir, exist_ok=True)
        out_json = os.path.join(out_dir, "bench-scaling.json")
        os.replace(tmp, out_json)
        paths.insert(0, out_json)
    if not paths:
        ap.error("give JSON files or --run")
    renders, raycasts, contexts = load_rows(paths)
    ctx = contexts[0]
    out_dir = a.out_dir or os.path.join("results", ctx.get("machine", "unknown-machine"))
    os.makedirs(out_dir, exist_ok=True)
    # Each file's machine with its own commit: the files may come from different commits.
    machines = sorted({c.get("cpu_model", "?") + (f" + {c['gpu_name']}" if "gpu_name" in c else "") +
                       f" (git {(str(c.get('git_revision') or '?').split() or ['?'])[0]})" for c in contexts})
    title = "\n".join(machines)
    plot_rays_vs_triangles(renders, raycasts, os.path.join(out_dir, "scaling-rays-vs-triangles.png"), title)
    plot_time_sweep(renders, os.path.join(out_dir, "scaling-time-vs-spp.png"),
                    f"{title}\nrender time vs spp (paper-cornell 128x128, nee)", lambda r: r["spp"],
                    "samples per pixel", lambda r: r["w"] == 128 and r["h"] == 128)
    plot_time_sweep(renders, os.path.join(out_dir, "scaling-time-vs-resolution.png"),
                    f"{title}\nrender time vs resolution (paper-cornell, 16 spp, nee)", lambda r: r["w"] * r["h"],
                    "pixels", lambda r: r["spp"] == 16)
    plot_memory(renders, os.path.join(out_dir, "scaling-memory.png"),
                f"{title}\nmemory vs pixels x spp (paper-cornell, nee)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
