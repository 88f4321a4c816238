#!/usr/bin/env python3
"""The README's "results at a glance" table, generated from the history's text export.

For every machine in results/history/runs/ and every device it ran, the latest recorded run
of the paper's frame (paper-cornell, 256x256, 800 spp, 2 bounces, light sampling): the median
render time per strategy, the commit and the date. The table sits between two markers in the
README; `--write README.md` rewrites it there, `--check README.md` exits 1 when it is stale.
"""
from __future__ import annotations

import argparse
import glob
import json
import re
import statistics
import sys
from pathlib import Path

from generated_block import update

ROOT = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- results-glance:begin (scripts/results_glance.py) -->", "<!-- results-glance:end -->"
FRAME = re.compile(r"^render/(cpu|gpu)/([a-z-]+)/paper-cornell/256x256/spp:800/bounces:2/nee/")
STRATEGIES = ("pixel", "wavefront", "paper-queue")


def latest_frames(runs_dir: Path) -> dict:
    """(machine, device) -> ((commit_date, run_date), commit, {strategy: median ms}, the device's name)."""
    best: dict = {}
    for path in sorted(glob.glob(str(runs_dir / "*.jsonl"))):
        lines = Path(path).read_text().splitlines()
        run = json.loads(lines[0])["run"]
        values: dict = {}
        for line in lines[1:]:
            row = json.loads(line)
            m = FRAME.match(row["benchmark"])
            if m and row.get("value") is not None and row.get("unit") == "ms":
                values.setdefault((m.group(1), m.group(2)), []).append(row["value"])
        when = run.get("commit_date") or run.get("run_date") or ""
        ctx = run.get("context") or {}
        names = {"cpu": ctx.get("cpu_model") or "", "gpu": ctx.get("gpu_name") or ""}
        for device in {d for d, _ in values}:
            key = (run["machine_name"], device)
            medians = {s: statistics.median(v) for (d, s), v in values.items() if d == device}
            if key not in best or (when, run.get("run_date") or "") > best[key][0]:
                best[key] = ((when, run.get("run_date") or ""), run["commit"][:7], medians, names[device])
    return best


def table(runs_dir: Path) -> str:
    rows = ["| machine (history name) | device | pixel | wavefront | paper-queue | commit | date |",
            "|---|---|---:|---:|---:|---|---|"]
    for (machine, device), ((when, _), commit, med, name) in sorted(latest_frames(runs_dir).items()):
        cells = [f"{med[s] / 1000:.2f} s" if med.get(s, 0) >= 1000 else f"{med[s]:.1f} ms" if s in med else "–"
                 for s in STRATEGIES]
        label = f"{device}: {name}" if name else device
        rows.append(f"| {machine} | {label} | " + " | ".join(cells) + f" | {commit} | {when[:10]} |")
    return "\n".join(rows)


def block(runs_dir: Path) -> str:
    return (f"{BEGIN}\nThe paper's frame (paper-cornell, 256×256, 800 spp, 2 bounces, light sampling), median render "
            f"time of the latest recorded run per machine and device (the paper: 27 s on a Tesla K20m):\n\n"
            f"{table(runs_dir)}\n{END}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, default=ROOT / "results" / "history" / "runs")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--write", type=Path, metavar="README", help="rewrite the table between the markers")
    g.add_argument("--check", type=Path, metavar="README", help="exit 1 if the table there is stale")
    a = ap.parse_args(argv)
    new = block(a.runs)
    target = a.write or a.check
    if target is None:
        print(new)
        return 0
    return update(target, BEGIN, END, new, check=bool(a.check), tool="results_glance",
                  remedy="scripts/maintainer/update-results.sh glance")

if __name__ == "__main__":
    sys.exit(main())
