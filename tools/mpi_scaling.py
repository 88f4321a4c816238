#!/usr/bin/env python3
"""MPI scaling study of `pathbench render` (issues 13, 30, 31): strong and weak scaling over
GPU and CPU ranks, the film reduction's share of the frame, the CPU+GPU hybrid against the
GPU alone, and whether every multi-rank image equals the one-rank image byte for byte.

    python3 tools/mpi_scaling.py --pathbench build/bin/pathbench [--mpirun mpirun.openmpi]
        [--gpus N] [--cpu-ranks 1,2,4] [--reps 3] [--hybrid-rounds 5] [--quick]
        [--out-dir results/<machine>/mpi-<commit>] [--record --commit SHA]

Experiments (GPU counts: 1, 2, 4, 8, ... up to --gpus, and --gpus itself):
  strong-gpu    fixed frames (paper 256x256x800 and 2048x2048x1024) on 1..N GPUs, one rank
                per GPU (rank r on GPU local_rank % visible GPUs)
  shared-gpu    2 x N ranks on N GPUs (two ranks per GPU): correctness only, not timed
                against anything (NCCL needs one rank per GPU: these reduce through MPI)
  weak-gpu      256x256 with 200 spp per rank: ideal is a flat frame time
  hybrid        one GPU rank + one CPU rank (MPMD, dynamic balancing) against the GPU alone,
                --hybrid-rounds interleaved rounds at each frame
  strong-cpu / weak-cpu   the same over --cpu-ranks CPU ranks
Every run's image and film hash is compared with the experiment's one-rank run (every
repetition, not only the median; film_hash_all keeps each repetition's), so a difference says
whether the film differed (its film_hash), only the file, or only the film (its 64-bit sums
below the float image's resolution): each is NOT IDENTICAL.

Times: a run's frame is from its start to the film on the host: N ranks' `ranks.frame_seconds`
(common start to the film reduced on rank 0), one process's `seconds` (host clock around its
frame, after its warm-up) plus its `film_download_seconds`. Speedup = T1 / TN, strong
efficiency = T1 / (N x TN), weak efficiency = T1 / TN (N ranks, N times the samples);
reduction share = reduce_seconds / frame seconds.

Writes <out-dir>/mpi-scaling.json (every run and summary rows), mpi-scaling.png (ideal and
measured speedup, weak efficiency, the reduction's share per N, the hybrid) and
mpi-scaling-history.json (a bench-shaped document `pathbench history record` takes: one
benchmark per experiment, frame and rank count, one repetition per run). --record records
it into the history (tools/history; results/history/runs/).
Exit status: 0, or 1 when an image differs from the one-rank image.
"""
from __future__ import annotations

import argparse
import datetime as dt
import hashlib
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
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def gpu_counts(n: int) -> list[int]:
    """1, 2, 4, ... up to n, and n itself."""
    out, k = [], 1
    while k <= n:
        out.append(k)
        k *= 2
    if n >= 1 and n not in out:
        out.append(n)
    return out


def machine_slug(report: dict) -> str:
    gpu = report.get("gpu") or {}
    if isinstance(gpu, dict) and gpu.get("slug"):
        return gpu["slug"]
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import machine  # tools/machine.py: the project's slug rule

    return machine.machine_slug()


def file_digest(path: str) -> str:
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


class Runner:
    def __init__(self, args):
        self.args = args
        self.tmp = tempfile.mkdtemp(prefix="mpi-scaling-")
        self.env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                        NCCL_NVLS_ENABLE="0")
        self.count = 0
        self.last_report: dict = {}
        self.gpu_report: dict = {}

    def render(self, lines: list[list[str]], frame, extra: list[str]) -> dict:
        """One run: `lines` are per-MPMD-line (np, device args). Each run writes its own
        image and report (run<k>.pfm / .json), never a path another run used."""
        self.count += 1
        w, h, spp = frame
        image = os.path.join(self.tmp, f"run{self.count}.pfm")
        report = os.path.join(self.tmp, f"run{self.count}.json")
        common = ["render", "--quiet", "--scene", "paper-cornell", "--width", str(w), "--height", str(h),
                  "--spp", str(spp), "--bounces", "2", "--out", image, "--report", report] + extra
        if len(lines) == 1 and lines[0][0] == "1":
            cmd = [self.args.pathbench] + common + lines[0][1:]
        else:
            cmd = [self.args.mpirun, "--oversubscribe", "--bind-to", "none"] + self.args.mpi_arg
            for i, line in enumerate(lines):
                if i:
                    cmd.append(":")
                cmd += ["-np", line[0], self.args.pathbench] + common + line[1:]
        print("+", " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True, env=self.env)
        with open(report) as f:
            self.last_report = json.load(f)
        if self.last_report.get("device") == "gpu":
            self.gpu_report = self.last_report
        # The image's bytes now, once the run has ended: later runs never touch this file.
        return {"report": self.last_report, "image": image, "image_sha256": file_digest(image),
                "film_hash": self.last_report.get("film_hash"), "seconds": frame_seconds(self.last_report)}

    def reps(self, lines, frame, extra=(), n=None) -> list[dict]:
        return [self.render(lines, frame, list(extra)) for _ in range(n or self.args.reps)]


def frame_seconds(report: dict) -> float:
    """From the frame's start to the film on the host (module docstring)."""
    ranks = report.get("ranks")
    if ranks:
        return float(ranks["frame_seconds"])
    return float(report["seconds"]) + float(report.get("film_download_seconds") or 0.0)


def median_run(runs: list[dict]) -> dict:
    return sorted(runs, key=lambda r: r["seconds"])[len(runs) // 2]


def compare(base: list[dict] | None, runs: list[dict]) -> dict:
    """Every run against the base's first run: the image's bytes and the film hash."""
    if not base:
        return {}
    ref = base[0]
    same_images = all(r["image_sha256"] == ref["image_sha256"] for r in runs + base)
    same_films = all(r["film_hash"] == ref["film_hash"] for r in runs + base)
    # Identical: the image bytes and the film (its 64-bit sums: a difference below a float's
    # resolution of the mean leaves the image's bytes as they were).
    out = {"identical": same_images and same_films, "image_identical": same_images,
           "film_hash_identical": same_films}
    if not (same_images and same_films):
        out["difference"] = ("the film differs (film_hash)" if same_images is same_films
                             else "the film differs while the image file is the same" if same_images
                             else "the image file differs while the film is the same")
        out["image_sha256"] = sorted({r["image_sha256"] for r in runs + base})
        out["film_hashes"] = sorted({str(r["film_hash"]) for r in runs + base})
        out["base_film_hash"] = ref["film_hash"]
    return out


def entry(kind: str, frame, n: int, runs: list[dict], base: list[dict] | None, timed_base: bool = True,
          **more) -> dict:
    m = median_run(runs)
    report = m["report"]
    ranks = report.get("ranks") or {}
    t = m["seconds"]
    e = {"experiment": kind, "width": frame[0], "height": frame[1], "spp": frame[2], "ranks": n, "seconds": t,
         "seconds_all": [r["seconds"] for r in runs],
         "film_hash_all": [r["film_hash"] for r in runs],
         # PATHBENCH_RANK_FILM_HASH=1 in the ranks' environment: each CPU rank's film before the reduction.
         "rank_film_hashes_all": [[p.get("film_hash") for p in (r["report"].get("ranks") or {}).get("per_rank", [])]
                                  for r in runs],
         # The Embree layout each CPU rank traced (rank 0's probe on every rank since issue 30's fix).
         "rank_layouts_all": [[(p.get("embree_layout") or {}).get("used")
                               for p in (r["report"].get("ranks") or {}).get("per_rank", [])] for r in runs],
         "rays_per_second": report["rays"]["total"] / t if t > 0 else None,
         "film_hash": m["film_hash"],
         "load_balance": ranks.get("load_balance"), "parallel_efficiency": ranks.get("parallel_efficiency"),
         "reduce_seconds": ranks.get("reduce_seconds"),
         "reduce_share": (ranks.get("reduce_seconds") or 0.0) / t if ranks and t > 0 else None,
         "reduction": ranks.get("reduction"), "device_share": ranks.get("device_share"),
         "balance": ranks.get("balance"), "per_rank": ranks.get("per_rank")}
    if base is not None and timed_base:
        t1 = median_run(base)["seconds"]
        e["base_seconds"] = t1
        e["speedup"] = t1 / t if t > 0 else None
        e["strong_efficiency"] = t1 / (n * t) if t > 0 else None
    e.update(compare(base, runs))
    e.update(more)
    return e


def experiments(r: Runner, args, save=lambda runs: None) -> list[dict]:
    """Every experiment's entries; `save(runs)` after each (a run cut short keeps what it has)."""
    frames = [(64, 64, 32), (128, 128, 64)] if args.quick else [PAPER, BIG]
    weak_spp = 8 if args.quick else WEAK_SPP
    cpu_ranks = [int(x) for x in args.cpu_ranks.split(",") if x]
    runs: list[dict] = []

    class Saved(list):
        def append(self, x):
            super().append(x)
            save(self)

    runs = Saved()
    if args.gpus > 0:
        counts = gpu_counts(args.gpus)
        for frame in frames:
            base = r.reps([["1", "--device", "gpu"]], frame)
            runs.append(entry("strong-gpu", frame, 1, base, base))
            for n in counts[1:]:
                runs.append(entry("strong-gpu", frame, n, r.reps([[str(n), "--device", "gpu"]], frame), base))
            # More ranks than GPUs (two per GPU): correctness only.
            n = 2 * args.gpus
            runs.append(entry("shared-gpu", frame, n, r.reps([[str(n), "--device", "gpu"]], frame, n=1), base,
                              timed_base=False, gpus=args.gpus))
        wbase = None
        for n in counts:
            frame = (frames[0][0], frames[0][1], weak_spp * n)
            reps = r.reps([[str(n), "--device", "gpu"]], frame)
            e = entry("weak-gpu", frame, n, reps, None)
            wbase = wbase or e["seconds"]
            e["weak_efficiency"] = wbase / e["seconds"] if e["seconds"] > 0 else None
            runs.append(e)
        # Hybrid: interleaved rounds of the GPU alone and GPU + CPU rank (dynamic chunks).
        for frame in frames:
            alone, hy = [], []
            for _ in range(args.hybrid_rounds):
                alone += r.reps([["1", "--device", "gpu"]], frame, n=1)
                hy += r.reps([["1", "--device", "gpu"], ["1", "--device", "cpu"]], frame, n=1)
            e = entry("hybrid", frame, 2, hy, alone)
            e["gpu_alone_seconds"] = median_run(alone)["seconds"]
            e["gpu_alone_seconds_all"] = [x["seconds"] for x in alone]
            # Round by round: hybrid / alone (>= 1: the hybrid is no slower).
            e["round_speedups"] = [a["seconds"] / h["seconds"] for a, h in zip(alone, hy)]
            runs.append(e)
    if cpu_ranks:
        frame = frames[0]
        base = r.reps([["1", "--device", "cpu"]], frame)
        for n in cpu_ranks:
            reps = base if n == 1 else r.reps([[str(n), "--device", "cpu"]], frame)
            runs.append(entry("strong-cpu", frame, n, reps, base))
        wbase = None
        for n in cpu_ranks:
            frame = (frames[0][0], frames[0][1], weak_spp * n)
            e = entry("weak-cpu", frame, n, r.reps([[str(n), "--device", "cpu"]], frame), None)
            wbase = wbase or e["seconds"]
            e["weak_efficiency"] = wbase / e["seconds"] if e["seconds"] > 0 else None
            runs.append(e)
    return list(runs)


def history_doc(doc: dict, runs: list[dict], commit: str | None) -> dict:
    """A bench-shaped document for `pathbench history record`: one benchmark per experiment,
    frame and rank count (its series), one repetition per run, real time in ms."""
    fp = doc.get("fingerprint") or {}
    now = dt.datetime.now(dt.timezone.utc).replace(microsecond=0).isoformat()
    context = {"date": now, "git_revision": commit or (doc.get("git_revision") or ""),
               "machine": doc["machine_name"], "fingerprint": fp, "pathbench_preset": "mpi-scaling",
               "mpi_ranks": "varies", "gpus": doc["gpus"], "tool": doc["tool"]}
    benchmarks = []
    for x in runs:
        name = (f"mpi/{x['experiment']}/paper-cornell/{x['width']}x{x['height']}/spp:{x['spp']}/"
                f"ranks:{x['ranks']}")
        counters = {k: x[k] for k in ("speedup", "strong_efficiency", "weak_efficiency", "reduce_share",
                                      "reduce_seconds", "parallel_efficiency", "load_balance")
                    if isinstance(x.get(k), (int, float))}
        if "identical" in x:
            counters["identical"] = 1.0 if x["identical"] else 0.0
        for i, s in enumerate(x["seconds_all"]):
            benchmarks.append({"name": name, "run_name": name, "run_type": "iteration", "repetition_index": i,
                               "iterations": 1, "real_time": s * 1e3, "cpu_time": s * 1e3, "time_unit": "ms",
                               **counters})
    return {"context": context, "benchmarks": benchmarks}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pathbench", default="build/bin/pathbench")
    ap.add_argument("--mpirun", default=shutil.which("mpirun.openmpi") or shutil.which("mpirun") or "mpirun")
    ap.add_argument("--mpi-arg", action="append", default=[], help="extra mpirun argument (repeatable)")
    ap.add_argument("--gpus", type=int, default=0, help="GPUs to scale over (0: CPU ranks only)")
    ap.add_argument("--cpu-ranks", default="1,2,4", help="CPU rank counts (empty: none)")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--hybrid-rounds", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="small frames (64x64x32, 128x128x64): a smoke test")
    ap.add_argument("--out-dir", default=None)
    ap.add_argument("--machine", default=None, help="the machine's name in the history (default: slug, xN GPUs)")
    ap.add_argument("--commit", default=None, help="the commit measured (history record)")
    ap.add_argument("--record", action="store_true", help="record mpi-scaling-history.json into the history")
    args = ap.parse_args()
    r = Runner(args)

    def document(runs: list[dict]) -> tuple[dict, str]:
        rep = r.gpu_report or r.last_report
        slug = machine_slug(rep)
        out_dir = args.out_dir or os.path.join("results", slug)
        os.makedirs(out_dir, exist_ok=True)
        doc = {"tool": "tools/mpi_scaling.py", "machine": rep.get("machine"), "gpu": rep.get("gpu"),
               "machine_name": args.machine or (f"{slug}-x{args.gpus}" if args.gpus else slug),
               "fingerprint": rep.get("fingerprint"), "git_revision": rep.get("git_revision"),
               "mpirun": args.mpirun, "mpi_args": args.mpi_arg, "gpus": args.gpus, "reps": args.reps,
               "hybrid_rounds": args.hybrid_rounds,
               "timing": "frame seconds: start to film on the host (N ranks: ranks.frame_seconds; one process: "
                         "seconds + film_download_seconds)",
               "runs": list(runs)}
        with open(os.path.join(out_dir, "mpi-scaling.json"), "w") as f:
            json.dump(doc, f, indent=1)
        return doc, out_dir

    runs = experiments(r, args, document)
    doc, out_dir = document(runs)
    print("wrote", os.path.join(out_dir, "mpi-scaling.json"))
    hist = os.path.join(out_dir, "mpi-scaling-history.json")
    with open(hist, "w") as f:
        json.dump(history_doc(doc, runs, args.commit), f, indent=1)
    print("wrote", hist)
    plot(runs, os.path.join(out_dir, "mpi-scaling.png"), doc["machine_name"])
    print(summary(runs))
    if args.record:
        subprocess.run([sys.executable, "-m", "tools.history", "record", os.path.abspath(hist)]
                       + (["--commit", args.commit] if args.commit else []), check=True, cwd=ROOT)
    shutil.rmtree(r.tmp, ignore_errors=True)
    bad = [x for x in runs if x.get("identical") is False]
    for x in bad:
        print(f"NOT IDENTICAL: {x['experiment']} {x['width']}x{x['height']}x{x['spp']} on {x['ranks']} ranks: "
              f"{x.get('difference')}")
    return 1 if bad else 0


def summary(runs: list[dict]) -> str:
    lines = ["| experiment | frame | ranks | seconds | speedup | efficiency | reduce share | reduction | identical |",
             "|---|---|---:|---:|---:|---:|---:|---|---|"]
    for x in runs:
        eff = x.get("strong_efficiency") if x["experiment"].startswith("strong") else x.get("weak_efficiency")
        red = (x.get("reduction") or {}).get("gpu_ranks", "")
        bands = (x.get("reduction") or {}).get("bands") or 1
        red += f", {bands} bands" if bands > 1 else ""
        f = lambda v, p=3: "" if v is None else f"{v:.{p}f}"  # noqa: E731
        lines.append(f"| {x['experiment']} | {x['width']}x{x['height']}x{x['spp']} | {x['ranks']} | "
                     f"{f(x['seconds'], 4)} | {f(x.get('speedup'), 2)} | {f(eff, 2)} | "
                     f"{f(x.get('reduce_share'), 3)} | {red} | {x.get('identical', '')} |")
    return "\n".join(lines)


def plot(runs: list[dict], path: str, machine: str) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot")
        return
    fig, ax = plt.subplots(1, 4, figsize=(19, 4.4))
    top = 1
    for kind, marker in (("strong-gpu", "o"), ("strong-cpu", "s")):
        frames = sorted({(x["width"], x["height"], x["spp"]) for x in runs if x["experiment"] == kind})
        for fr in frames:
            xs = [x for x in runs if x["experiment"] == kind and (x["width"], x["height"], x["spp"]) == fr]
            top = max([top] + [x["ranks"] for x in xs])
            ax[0].plot([x["ranks"] for x in xs], [x.get("speedup") for x in xs], marker=marker,
                       label=f"{kind} {fr[0]}x{fr[1]}x{fr[2]}")
    ax[0].plot([1, top], [1, top], "k:", label="ideal")
    ax[0].set(title="strong scaling", xlabel="ranks (GPU ranks: GPUs)", ylabel="speedup over one rank")
    ax[0].legend(fontsize=7)
    for kind in ("weak-gpu", "weak-cpu"):
        xs = [x for x in runs if x["experiment"] == kind]
        if xs:
            ax[1].plot([x["ranks"] for x in xs], [x.get("weak_efficiency") for x in xs], marker="o", label=kind)
    ax[1].axhline(1.0, color="k", ls=":", label="ideal")
    ax[1].set(title="weak scaling (200 spp per rank)", xlabel="ranks", ylabel="efficiency T1 / TN", ylim=(0, 1.1))
    ax[1].legend(fontsize=7)
    red = [x for x in runs if x["experiment"] == "strong-gpu" and x["ranks"] > 1]
    labels = [f"{x['width']}x{x['spp']}\n{x['ranks']} GPUs" for x in red]
    shares = [100 * (x.get("reduce_share") or 0) for x in red]
    ax[2].bar(range(len(red)), [100 - s for s in shares], color="tab:green", label="tracing and waiting")
    ax[2].bar(range(len(red)), shares, bottom=[100 - s for s in shares], color="tab:red", label="film reduction")
    for i, s in enumerate(shares):
        ax[2].text(i, 101, f"{s:.1f}%", ha="center", fontsize=7)
    ax[2].set_xticks(range(len(red)), labels, fontsize=7)
    ax[2].set(title="share of the frame (strong-gpu)", ylabel="% of frame seconds", ylim=(0, 110))
    ax[2].legend(fontsize=7, loc="lower right")
    hy = [x for x in runs if x["experiment"] == "hybrid"]
    for i, x in enumerate(hy):
        rounds = x.get("round_speedups") or [x.get("speedup")]
        ax[3].scatter([i] * len(rounds), rounds, color="tab:purple", label="rounds" if not i else None)
        ax[3].plot([i - 0.2, i + 0.2], [x.get("speedup")] * 2, color="k", label="median" if not i else None)
        share = x.get("device_share") or {}
        ax[3].text(i, max(rounds) * 1.005, f"cpu {100 * share.get('cpu', 0):.3f}% of samples", ha="center", fontsize=7)
    ax[3].axhline(1.0, color="k", ls=":", label="GPU alone")
    ax[3].set_xticks(range(len(hy)), [f"{x['width']}x{x['height']}x{x['spp']}" for x in hy])
    ax[3].set(title="hybrid GPU+CPU rank vs the GPU alone", ylabel="speedup (GPU alone / hybrid)")
    if hy:
        ax[3].legend(fontsize=7)
    fig.suptitle(f"pathbench MPI scaling, {machine}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("wrote", path)


if __name__ == "__main__":
    sys.exit(main())
