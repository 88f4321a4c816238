#!/usr/bin/env python3
"""Interleaved A/B rounds of scripts/mpi_device_check.sh (issue 30), summarised:

  cache/  the hybrid (one GPU rank + one CPU rank) with gpu::render's kept per-call setup
          (`on-<width>-<i>.json`) and without it (PATHBENCH_GPU_RENDER_CACHE=0,
          `off-<width>-<i>.json`), against one GPU process (`gpu-<width>-<i>.json`), round by round
  bands/  2 GPU ranks reducing the film at the end (`b1-<width>-<i>.json`) against band by
          band while tracing (`b<k>-...`, `bauto-...`: PATHBENCH_REDUCE_BANDS)

Times are tools/mpi_scaling.py's: from the frame's start to the film on the host. Prints
Markdown tables (median, min-max, per-round ratios) and writes DIR/ab.json.

    python3 tools/mpi_scaling_ab.py DIR
Exit status: 0, or 2 when DIR holds neither folder.
"""
from __future__ import annotations

import glob
import json
import os
import re
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mpi_scaling import frame_seconds  # noqa: E402

NAME = re.compile(r"^(?P<arm>[a-z0-9]+)-(?P<width>\d+)-(?P<round>\d+)\.json$")


def load(folder: str) -> dict:
    """{(arm, width): {round: report}}"""
    out: dict = {}
    for path in sorted(glob.glob(os.path.join(folder, "*.json"))):
        m = NAME.match(os.path.basename(path))
        if not m:
            continue
        with open(path) as f:
            rep = json.load(f)
        out.setdefault((m["arm"], int(m["width"])), {})[int(m["round"])] = rep
    return out


def stats(xs: list[float]) -> dict:
    return {"median": statistics.median(xs), "min": min(xs), "max": max(xs), "n": len(xs)} if xs else {}


def reduce_share(rep: dict) -> float | None:
    r = rep.get("ranks") or {}
    return (r.get("reduction") or {}).get("share_of_frame")


def summarise(runs: dict, base_arm: str) -> list[dict]:
    """Each arm against `base_arm` at each width: times, and per round base / arm (>= 1: the arm
    is no slower than the base)."""
    rows = []
    for (arm, width), reps in sorted(runs.items(), key=lambda kv: (kv[0][1], kv[0][0])):
        times = {i: frame_seconds(r) for i, r in reps.items()}
        row = {"arm": arm, "width": width, "seconds": stats(list(times.values())),
               "reduce_seconds": stats([float((r.get("ranks") or {}).get("reduce_seconds") or 0.0)
                                        for r in reps.values() if r.get("ranks")]),
               "reduce_share": stats([s for s in (reduce_share(r) for r in reps.values()) if s is not None]),
               "bands": sorted({((r.get("ranks") or {}).get("reduction") or {}).get("bands") for r in reps.values()
                                if r.get("ranks")} - {None}),
               "film_hashes": sorted({str(r.get("film_hash")) for r in reps.values()})}
        base = runs.get((base_arm, width), {})
        if arm != base_arm and base:
            ratios = [frame_seconds(base[i]) / t for i, t in sorted(times.items()) if i in base and t > 0]
            row["round_ratios"] = ratios
            row["ratio"] = stats(ratios)
        rows.append(row)
    return rows


def table(rows: list[dict], title: str, base_arm: str) -> str:
    ms = lambda s: f"{1e3 * s['median']:.3f} ({1e3 * s['min']:.3f}-{1e3 * s['max']:.3f})" if s else ""  # noqa: E731
    out = [f"### {title}", "",
           f"| width | arm | frame ms median (min-max) | reduce ms | reduce share | {base_arm} / arm per round | bands |",
           "|---:|---|---:|---:|---:|---|---|"]
    for r in rows:
        share = r["reduce_share"]
        share_txt = f"{100 * share['median']:.2f} %" if share else ""
        ratio = " ".join(f"{x:.3f}" for x in r.get("round_ratios", []))
        if r.get("ratio"):
            ratio = f"**{r['ratio']['median']:.3f}** ({ratio})"
        out.append(f"| {r['width']} | {r['arm']} | {ms(r['seconds'])} | "
                   f"{ms(r['reduce_seconds']) if r['reduce_seconds'] else ''} | "
                   f"{share_txt} | {ratio} | "
                   f"{','.join(map(str, r['bands']))} |")
    return "\n".join(out)


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: tools/mpi_scaling_ab.py DIR", file=sys.stderr)
        return 2
    d = argv[0]
    doc, parts = {}, []
    for sub, base, title in (("cache", "gpu", "hybrid (1 GPU + 1 CPU rank) with and without the kept render setup, "
                                              "against one GPU process"),
                             ("bands", "b1", "2 GPU ranks: film reduced at the end (b1) or band by band")):
        folder = os.path.join(d, sub)
        if not os.path.isdir(folder):
            continue
        runs = load(folder)
        rows = summarise(runs, base)
        doc[sub] = {"rows": rows, "film_hashes_per_width": {
            str(w): sorted({str(r.get("film_hash")) for (a, ww), reps in runs.items() if ww == w
                            for r in reps.values()}) for w in sorted({w for _, w in runs})}}
        parts.append(table(rows, title, base))
    if not doc:
        print(f"mpi_scaling_ab: {d} holds neither cache/ nor bands/", file=sys.stderr)
        return 2
    with open(os.path.join(d, "ab.json"), "w") as f:
        json.dump(doc, f, indent=1)
    print("\n\n".join(parts))
    for sub, x in doc.items():
        for w, hashes in x["film_hashes_per_width"].items():
            print(f"{sub} {w}: {'one film hash' if len(hashes) == 1 else 'FILM HASHES DIFFER: ' + ' '.join(hashes)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
