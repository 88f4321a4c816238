#!/usr/bin/env python3
"""Per-kernel speed-of-light figures of the GPU tracer from scripts/device/gpu_roofline.sh's ncu
CSV files: for every kernel, launches, time, achieved instruction issue rate (% of the
SMs' issue slots while active), SM and memory throughput (% of peak: DRAM, L2, L1),
DRAM bandwidth in GB/s, occupancy, SIMT efficiency (active threads per instruction / 32)
and registers. A kernel near 100% on the issue axis is issue bound; near 100% on a
memory axis, bandwidth bound; low on both, latency bound (waiting on dependent loads or
divergence) — the distance to the nearer ceiling is what is left to win.

    tools/roofline.py DIR [--out-json F] [--out-md F] [--plot F.png]

Writes JSON (one object per run and kernel), a Markdown table and, with matplotlib, a
chart: memory throughput (x) against issue rate (y), both as % of peak, one point per
kernel sized by its share of the run's time.
"""
from __future__ import annotations

import argparse
import csv
import json
import re
import sys
from collections import defaultdict
from pathlib import Path

TIME_UNITS = {"nsecond": 1e-9, "usecond": 1e-6, "msecond": 1e-3, "second": 1.0, "ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
BYTE_UNITS = {"byte": 1, "Kbyte": 1e3, "Mbyte": 1e6, "Gbyte": 1e9, "Tbyte": 1e12}


def number(text: str) -> float:
    return float(text.replace(",", ""))


def kernel_name(full: str) -> str:
    """'void pb::gpu::k_wf_shade<...>(SceneView, ...)' -> 'k_wf_shade'."""
    head = full.split("(")[0]
    head = re.sub(r"<.*", "", head)
    return head.split()[-1].split("::")[-1]


def read_launches(path: Path) -> list[dict]:
    """One dict per profiled launch: kernel name and metric -> value in base units."""
    rows = [line for line in path.read_text(errors="replace").splitlines() if line.startswith('"')]
    launches: dict[str, dict] = {}
    for rec in csv.DictReader(rows):
        if "Metric Name" not in rec or rec.get("ID") is None:
            continue
        launch = launches.setdefault(rec["ID"], {"kernel": kernel_name(rec["Kernel Name"])})
        value, unit = rec["Metric Value"], rec.get("Metric Unit", "")
        try:
            v = number(value)
        except ValueError:
            continue
        v *= TIME_UNITS.get(unit, 1.0) * BYTE_UNITS.get(unit, 1)
        launch[rec["Metric Name"]] = v
    return list(launches.values())


def summarise(launches: list[dict]) -> list[dict]:
    """Per kernel: time-weighted means of the rates, sums of time and bytes."""
    by_kernel: dict[str, list[dict]] = defaultdict(list)
    for launch in launches:
        by_kernel[launch["kernel"]].append(launch)
    total = sum(l.get("gpu__time_duration.sum", 0) for l in launches) or 1.0
    out = []
    for name, ls in by_kernel.items():
        t = sum(l.get("gpu__time_duration.sum", 0) for l in ls) or 1e-30

        def mean(key):
            vals = [(l[key], l.get("gpu__time_duration.sum", 0)) for l in ls if key in l]
            w = sum(d for _, d in vals)
            return sum(v * d for v, d in vals) / w if w > 0 else None

        dram_bytes = sum(l.get("dram__bytes.sum", 0) for l in ls)
        insts = sum(l.get("sm__inst_executed.sum", 0) for l in ls)
        simt = mean("smsp__thread_inst_executed_per_inst_executed.ratio")
        row = {
            "kernel": name, "launches": len(ls), "seconds": t, "share_of_time": t / total,
            "issue_pct_of_peak": mean("sm__inst_issued.avg.pct_of_peak_sustained_active"),
            "ipc_per_sm": mean("sm__inst_issued.avg.per_cycle_active"),
            "instructions_per_second": insts / t,
            "sm_throughput_pct": mean("sm__throughput.avg.pct_of_peak_sustained_elapsed"),
            "memory_throughput_pct": mean("gpu__compute_memory_throughput.avg.pct_of_peak_sustained_elapsed"),
            "dram_pct": mean("dram__throughput.avg.pct_of_peak_sustained_elapsed"),
            "l2_pct": mean("lts__t_sectors.avg.pct_of_peak_sustained_elapsed"),
            "l1_pct": mean("l1tex__t_sectors.avg.pct_of_peak_sustained_elapsed"),
            "dram_gb_per_s": dram_bytes / t / 1e9,
            "occupancy_pct": mean("sm__warps_active.avg.pct_of_peak_sustained_active"),
            "simt_efficiency": simt / 32 if simt is not None else None,
            "registers": mean("launch__registers_per_thread"),
            "sm_clock_hz": mean("sm__cycles_elapsed.avg.per_second"),
        }
        issue, mem = row["issue_pct_of_peak"] or 0, row["memory_throughput_pct"] or 0
        row["bound"] = "issue" if issue >= 60 and issue >= mem else "memory" if mem >= 60 else "latency"
        out.append(row)
    return sorted(out, key=lambda r: -r["seconds"])


def fmt(v, spec):
    return "-" if v is None else format(v, spec)


def markdown(runs: dict[str, list[dict]]) -> str:
    lines = ["| run | kernel | launches | time share | issue % | SM % | memory % | DRAM % | L2 % | L1 % | DRAM GB/s "
             "| occupancy % | SIMT eff. | regs | bound |", "|" + "---|" * 15]
    for run, rows in runs.items():
        for r in rows:
            lines.append(f"| {run} | {r['kernel']} | {r['launches']} | {fmt(100 * r['share_of_time'], '.0f')}% "
                         f"| {fmt(r['issue_pct_of_peak'], '.1f')} | {fmt(r['sm_throughput_pct'], '.1f')} "
                         f"| {fmt(r['memory_throughput_pct'], '.1f')} | {fmt(r['dram_pct'], '.1f')} "
                         f"| {fmt(r['l2_pct'], '.1f')} | {fmt(r['l1_pct'], '.1f')} | {fmt(r['dram_gb_per_s'], '.0f')} "
                         f"| {fmt(r['occupancy_pct'], '.1f')} | {fmt(r['simt_efficiency'], '.2f')} "
                         f"| {fmt(r['registers'], '.0f')} | {r['bound']} |")
    return "\n".join(lines) + "\n"


def plot(runs: dict[str, list[dict]], path: Path) -> None:
    import matplotlib  # noqa: PLC0415
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    fig, ax = plt.subplots(figsize=(7.5, 6))
    markers = "osD^v<>p"
    for i, (run, rows) in enumerate(runs.items()):
        xs = [r["memory_throughput_pct"] or 0 for r in rows]
        ys = [r["issue_pct_of_peak"] or 0 for r in rows]
        sizes = [30 + 400 * r["share_of_time"] for r in rows]
        ax.scatter(xs, ys, s=sizes, marker=markers[i % len(markers)], alpha=0.7, label=run)
        for r, x, y in zip(rows, xs, ys):
            if r["share_of_time"] >= 0.05:
                ax.annotate(r["kernel"], (x, y), fontsize=7, xytext=(4, 3), textcoords="offset points")
    ax.plot([0, 100], [100, 100], "k--", lw=0.8)
    ax.plot([100, 100], [0, 100], "k--", lw=0.8)
    ax.set_xlim(0, 105)
    ax.set_ylim(0, 105)
    ax.set_xlabel("memory throughput, % of peak (max of DRAM, L2, L1)")
    ax.set_ylabel("instruction issue, % of peak (active SMs)")
    ax.set_title("GPU tracer kernels against the device's ceilings (ncu)")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir", type=Path)
    ap.add_argument("--out-json", type=Path)
    ap.add_argument("--out-md", type=Path)
    ap.add_argument("--plot", type=Path)
    a = ap.parse_args(argv)
    runs = {}
    for csv_path in sorted(a.dir.glob("*.csv")):
        if csv_path.name == "nvidia-smi.csv":
            continue
        launches = read_launches(csv_path)
        if launches:
            runs[csv_path.stem] = summarise(launches)
    if not runs:
        print(f"roofline.py: no ncu launches in {a.dir}/*.csv", file=sys.stderr)
        return 2
    md = markdown(runs)
    print(md)
    if a.out_json:
        a.out_json.write_text(json.dumps({"runs": runs}, indent=2) + "\n")
    if a.out_md:
        a.out_md.write_text(md)
    if a.plot:
        plot(runs, a.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
