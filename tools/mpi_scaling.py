#!/usr/bin/env python3
"""MPI scaling study of `pathbench render` (issue 13): strong and weak scaling over GPU and
CPU ranks, the CPU+GPU hybrid's share, the film reduction's cost, and whether every
multi-rank image equals the one-rank image byte for byte.

    python3 tools/mpi_scaling.py --pathbench build/bin/pathbench [--mpirun mpirun.openmpi]
        [--gpus 2] [--cpu-ranks 1,2,4] [--reps 3] [--quick] [--out-dir results/<machine>]

Writes <out-dir>/mpi-scaling.json (every run: ranks, devices, frame seconds, speedup
and efficiency against one rank, load balance, parallel efficiency, reduction seconds,
device share, identical) and mpi-scaling.png. <out-dir> defaults to results/<slug of
the GPU> when --gpus > 0, else results/<slug of the CPU> (tools/machine.py).

Experiments:
  strong-gpu   fixed frames (paper 256x256x800 and 2048x2048x1024), 1..--gpus GPU ranks;
               with --gpus 1, also 2 ranks sharing the GPU (correctness only: "shared_gpu")
  strong-cpu   paper 256x256x800 over --cpu-ranks CPU ranks (each its share of the cores)
  weak-gpu/cpu 256x256 with 200 spp per rank: ideal is a flat frame time
  hybrid       GPU rank + CPU rank (MPMD, dynamic balancing) against the GPU alone:
               frame time, each device's share of the samples, identical image
Speedup = T1 / TN, strong efficiency = T1 / (N x TN) with T the frame's seconds as the
report gives them (one rank: the render; N ranks: common start to the reduced film).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

PAPER = (256, 256, 800)
BIG = (2048, 2048, 1024)
WEAK_SPP = 200


def machine_slug(report: dict) -> str:
    gpu = report.get("gpu") or {}
    if isinstance(gpu, dict) and gpu.get("slug"):
        return gpu["slug"]
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import machine  # tools/machine.py: the project's slug rule

    return machine.machine_slug()


class Runner:
    def __init__(self, args):
        self.args = args
        self.tmp = tempfile.mkdtemp(prefix="mpi-scaling-")
        self.env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                        NCCL_NVLS_ENABLE="0")
        self.count = 0
        self.last_report: dict = {}

    def render(self, lines: list[list[str]], frame, extra: list[str]) -> tuple[dict, str]:
        """One run: `lines` are per-MPMD-line (np, device args); returns (report, image path)."""
        self.count += 1
        w, h, spp = frame
        image = os.path.join(self.tmp, f"run{self.count}.pfm")
        report = os.path.join(self.tmp, f"run{self.count}.json")
        common = ["render", "--quiet", "--scene", "paper-cornell", "--width", str(w), "--height", str(h),
                  "--spp", str(spp), "--bounces", "2", "--out", image, "--report", report] + extra
        if len(lines) == 1 and lines[0][0] == "1":
            cmd = [self.args.pathbench] + common + lines[0][1:]
        else:
            cmd = [self.args.mpirun, "--oversubscribe", "--bind-to", "none"]
            for i, line in enumerate(lines):
                if i:
                    cmd.append(":")
                cmd += ["-np", line[0], self.args.pathbench] + common + line[1:]
        print("+", " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True, env=self.env)
        with open(report) as f:
            self.last_report = json.load(f)
        return self.last_report, image

    def best(self, lines, frame, extra=()) -> tuple[dict, str]:
        """--reps runs; the one of median frame time."""
        runs = [self.render(lines, frame, list(extra)) for _ in range(self.args.reps)]
        runs.sort(key=lambda r: frame_seconds(r[0]))
        return runs[len(runs) // 2]


def frame_seconds(report: dict) -> float:
    ranks = report.get("ranks")
    if ranks:
        return float(ranks["frame_seconds"])
    # One rank: the device's own time (CUDA events on the GPU, wall clock on the CPU).
    return float(report["device_seconds"] if report.get("device") == "gpu" else report["seconds"])


def same_file(a: str, b: str) -> bool:
    with open(a, "rb") as fa, open(b, "rb") as fb:
        return fa.read() == fb.read()


def entry(kind: str, frame, n: int, report: dict, image: str, base: tuple[dict, str] | None, **more) -> dict:
    ranks = report.get("ranks") or {}
    t = frame_seconds(report)
    e = {"experiment": kind, "width": frame[0], "height": frame[1], "spp": frame[2], "ranks": n, "seconds": t,
         "rays_per_second": report["rays"]["total"] / t if t > 0 else None,
         "load_balance": ranks.get("load_balance"), "parallel_efficiency": ranks.get("parallel_efficiency"),
         "reduce_seconds": ranks.get("reduce_seconds"), "device_share": ranks.get("device_share"),
         "balance": ranks.get("balance"), "per_rank": ranks.get("per_rank")}
    if base is not None:
        t1 = frame_seconds(base[0])
        e["speedup"] = t1 / t if t > 0 else None
        e["strong_efficiency"] = t1 / (n * t) if t > 0 else None
        e["identical"] = same_file(base[1], image)
    e.update(more)
    return e


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pathbench", default="build/bin/pathbench")
    ap.add_argument("--mpirun", default=shutil.which("mpirun.openmpi") or shutil.which("mpirun") or "mpirun")
    ap.add_argument("--gpus", type=int, default=0, help="GPUs to scale over (0: CPU ranks only)")
    ap.add_argument("--cpu-ranks", default="1,2,4", help="CPU rank counts (empty: none)")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="small frames (64x64x32): a smoke test of the script")
    ap.add_argument("--out-dir", default=None)
    args = ap.parse_args()
    r = Runner(args)
    frames = [(64, 64, 32)] if args.quick else [PAPER, BIG]
    weak_spp = 8 if args.quick else WEAK_SPP
    cpu_ranks = [int(x) for x in args.cpu_ranks.split(",") if x]
    runs: list[dict] = []

    if args.gpus > 0:
        for frame in frames:
            base = r.best([["1", "--device", "gpu"]], frame)
            runs.append(entry("strong-gpu", frame, 1, *base, base))
            counts = list(range(2, args.gpus + 1)) or [2]
            for n in counts:
                rep, img = r.best([[str(n), "--device", "gpu"]], frame)
                runs.append(entry("strong-gpu", frame, n, rep, img, base, shared_gpu=args.gpus < n))
        wbase = None
        for n in range(1, max(args.gpus, 1) + 1):
            frame = (256, 256, weak_spp * n)
            rep, img = r.best([[str(n), "--device", "gpu"]], frame)
            runs.append(entry("weak-gpu", frame, n, rep, img, None))
        # Hybrid: one GPU rank and one CPU rank (the rest of the cores), dynamic chunks.
        for frame in frames:
            gpu_alone = r.best([["1", "--device", "gpu"]], frame)
            rep, img = r.best([["1", "--device", "gpu"], ["1", "--device", "cpu"]], frame, ["--balance", "dynamic"])
            runs.append(entry("hybrid", frame, 2, rep, img, gpu_alone,
                              gpu_alone_seconds=frame_seconds(gpu_alone[0])))
    if cpu_ranks:
        frame = frames[0]
        base = r.best([["1", "--device", "cpu"]], frame)
        for n in cpu_ranks:
            rep, img = (base if n == 1 else r.best([[str(n), "--device", "cpu"]], frame))
            runs.append(entry("strong-cpu", frame, n, rep, img, base))
        for n in cpu_ranks:
            frame = (256, 256, weak_spp * n)
            rep, img = r.best([[str(n), "--device", "cpu"]], frame)
            runs.append(entry("weak-cpu", frame, n, rep, img, None))

    out_dir = args.out_dir or os.path.join("results", machine_slug(r.last_report))
    os.makedirs(out_dir, exist_ok=True)
    doc = {"tool": "tools/mpi_scaling.py", "machine": r.last_report.get("machine"),
           "fingerprint": r.last_report.get("fingerprint"), "mpirun": args.mpirun, "gpus": args.gpus,
           "reps": args.reps, "runs": runs}
    path = os.path.join(out_dir, "mpi-scaling.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
    print("wrote", path)
    plot(runs, os.path.join(out_dir, "mpi-scaling.png"))
    shutil.rmtree(r.tmp, ignore_errors=True)
    bad = [x for x in runs if x.get("identical") is False and x["experiment"] != "hybrid"]
    for x in bad:
        print(f"NOT IDENTICAL: {x['experiment']} {x['width']}x{x['height']}x{x['spp']} on {x['ranks']} ranks")
    return 1 if bad else 0


def plot(runs: list[dict], path: str) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot")
        return
    fig, ax = plt.subplots(1, 4, figsize=(18, 4.2))
    for kind, marker in (("strong-gpu", "o"), ("strong-cpu", "s")):
        frames = sorted({(x["width"], x["height"], x["spp"]) for x in runs if x["experiment"] == kind})
        for fr in frames:
            xs = [x for x in runs if x["experiment"] == kind and (x["width"], x["height"], x["spp"]) == fr]
            ax[0].plot([x["ranks"] for x in xs], [x.get("speedup") for x in xs], marker=marker,
                       label=f"{kind} {fr[0]}x{fr[1]}x{fr[2]}")
    if any(x["experiment"].startswith("strong") for x in runs):
        top = max(x["ranks"] for x in runs if x["experiment"].startswith("strong"))
        ax[0].plot([1, top], [1, top], "k:", label="ideal")
    ax[0].set(title="strong scaling", xlabel="ranks", ylabel="speedup over one rank")
    ax[0].legend(fontsize=7)
    for kind in ("weak-gpu", "weak-cpu"):
        xs = [x for x in runs if x["experiment"] == kind]
        if xs:
            ax[1].plot([x["ranks"] for x in xs], [x["seconds"] for x in xs], marker="o", label=kind)
    ax[1].set(title=f"weak scaling (spp per rank fixed)", xlabel="ranks", ylabel="frame seconds")
    ax[1].legend(fontsize=7)
    hy = [x for x in runs if x["experiment"] == "hybrid"]
    for i, x in enumerate(hy):
        share = x.get("device_share") or {}
        ax[2].bar([i - 0.2], [x["gpu_alone_seconds"]], width=0.4, color="tab:green", label="GPU alone" if not i else None)
        ax[2].bar([i + 0.2], [x["seconds"]], width=0.4, color="tab:purple", label="GPU + CPU" if not i else None)
        ax[2].text(i + 0.2, x["seconds"], f"cpu {100 * share.get('cpu', 0):.1f}%", ha="center", va="bottom", fontsize=7)
    ax[2].set_xticks(range(len(hy)), [f"{x['width']}x{x['height']}x{x['spp']}" for x in hy])
    ax[2].set(title="hybrid CPU+GPU", ylabel="frame seconds")
    if hy:
        ax[2].legend(fontsize=7)
    red = [x for x in runs if x.get("reduce_seconds") is not None]
    ax[3].scatter([x["width"] * x["height"] for x in red], [1e3 * x["reduce_seconds"] for x in red],
                  c=[x["ranks"] for x in red])
    ax[3].set(title="film reduction onto rank 0", xlabel="pixels", ylabel="ms", xscale="log")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("wrote", path)


if __name__ == "__main__":
    sys.exit(main())
