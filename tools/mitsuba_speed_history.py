"""tools/mitsuba_speed.py's runs in the project history (tools/history): the results as a bench
JSON that `pathbench history record` imports, one series per pathbench run against Mitsuba:

    mitsuba/cpu/<scene>/<W>x<H>/spp:<spp>/bounces:2/nee/<strategy>[/<flags>][/emulate:<isa>]

one repetition per round, its value pathbench's time over Mitsuba's in that round (unit "ratio",
lower is better, as every history series; 0.5 is twice as fast as Mitsuba), with the round's
speed-up, both round medians and both overall medians as counters. The context carries the
machine fingerprint (tools/machine.py), so the history keys the machine by it."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from mitsuba_speed_report import round_medians

ROOT = Path(__file__).resolve().parent.parent


def series_name(res, label):
    s = res["settings"]
    em = res.get("emulation")
    return (f"mitsuba/cpu/{s['scene']}/{s['width']}x{s['height']}/spp:{s['spp']}/bounces:{s['bounces']}/"
            f"{s['sampling']}/{label}" + (f"/emulate:{em['isa']}" if em else ""))


def bench_json(res, date_iso):
    """The results as Google-Benchmark-shaped JSON (context + one row per series and round)."""
    m = res["mitsuba"]
    rev = next(iter(res["pathbench"].values())).get("git_revision") or ""
    context = {
        # "abc123-dirty": the commit, and the tree had changes (the history keys runs by the commit)
        "date": date_iso, "git_revision": rev.removesuffix("-dirty") or None, "git_dirty": rev.endswith("-dirty"), "machine": res["machine"]["slug"],
        "cpu_model": res["machine"]["cpu"], "fingerprint": res["fingerprint"],
        "pathbench_preset": "mitsuba-speed", "mitsuba": f"{m['renderer']} {m['variant']}",
        "load_average_before": res["load_average_before"], "load_average_after": res["load_average_after"],
        "settings": res["settings"],
    }
    m_round = round_medians(m["runs"])
    rows = []
    for label, r in res["pathbench"].items():
        p_round = round_medians(r["runs"])
        for i, k in enumerate(sorted(m_round.keys() & p_round.keys())):
            rows.append({
                "name": series_name(res, label), "run_type": "iteration", "repetition_index": i, "iterations": 1,
                "real_time": round(p_round[k] / m_round[k], 4), "time_unit": "ratio",
                "speedup_vs_mitsuba": round(m_round[k] / p_round[k], 4),
                "pathbench_seconds": round(p_round[k], 4), "mitsuba_seconds": round(m_round[k], 4),
                "pathbench_median_seconds": r["median_seconds"], "mitsuba_median_seconds": m["median_seconds"],
            })
    return {"context": context, "benchmarks": rows}


def record(path: Path, db: str | None = None) -> int:
    """`pathbench history record PATH` (into db, default the project's results/history); its exit status."""
    cmd = [sys.executable, "-m", "history", "record", str(path)] + (["--db", db] if db else [])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT / "tools"),
                                                                    os.environ.get("PYTHONPATH")])))
    return subprocess.run(cmd, cwd=ROOT, env=env).returncode
