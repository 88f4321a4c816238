"""The suite's rows (one per workload and device) from bench JSON, and what they are compared
with: this machine's previous run (the history database) and the reference machines (the
history's text export, results/history/runs/)."""
from __future__ import annotations

import glob
import json
import math
import os
import re
import sqlite3
import statistics

THRESHOLD = 0.05  # as `pathbench compare`: a change below 5 % is "same"
ALPHA = 0.05


def _median(xs):
    xs = [x for x in xs if isinstance(x, (int, float)) and math.isfinite(x)]
    return statistics.median(xs) if xs else None


def _time_ms(row: dict) -> float | None:
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}.get(row.get("time_unit", "ns"))
    t = row.get("real_time")
    return t * scale if isinstance(t, (int, float)) and scale else None


def series(benchmark: str) -> str:
    """A benchmark's series across runs: its name without Google Benchmark's /iterations:N (a
    fixed iteration count, which the suite's large workloads had while every frame rebuilt
    the BVH) and /manual_time."""
    return re.sub(r"(/iterations:\d+)?(/manual_time)?$", "", benchmark)


def rows_from_bench(doc: dict, cases: list[dict], device: dict) -> list[dict]:
    """One row per case: medians over the repetitions, or status 'failed' with the error."""
    ctx = doc.get("context", {})
    hashes = ctx.get("film_hashes", {}) if isinstance(ctx.get("film_hashes"), dict) else {}
    no_energy = ctx.get("energy_unavailable", {}) if isinstance(ctx.get("energy_unavailable"), dict) else {}
    by_name: dict[str, list[dict]] = {}
    errors: dict[str, str] = {}
    full: dict[str, str] = {}  # case name -> the JSON's (and the history's) name: ".../manual_time"
    for b in doc.get("benchmarks", []):
        name = b.get("run_name", b.get("name", ""))
        short = series(name)
        full[short] = name
        name = short
        if b.get("error_occurred"):
            errors[name] = b.get("error_message", "error")
        elif b.get("run_type", "iteration") == "iteration":
            by_name.setdefault(name, []).append(b)
    out = []
    for c in cases:
        reps = by_name.get(c["name"], [])
        base = {"workload": c["workload"], "device": device["label"], "device_name": device.get("name", ""),
                "benchmark": full.get(c["name"], c["name"] + "/manual_time"), "settings": c["settings"]}
        if not reps:
            why = errors.get(c["name"], "no result (pathbench-bench stopped before it)")
            base.update(status="skipped", reason=why)
            out.append(base)
            continue
        times = [_time_ms(r) for r in reps]
        ms = _median(times)
        spf = c["settings"]["width"] * c["settings"]["height"] * c["settings"]["spp"]

        def med(key):
            return _median([r.get(key) for r in reps])

        def peak(key):
            vals = [r.get(key) for r in reps if isinstance(r.get(key), (int, float))]
            return max(vals) if vals else None
        label = reps[-1].get("label", "")
        isa = next((p.split("=", 1)[1] for p in label.split() if p.startswith("isa=")), None)
        throttled = any((r.get("throttled") or 0) > 0 for r in reps) if any("throttled" in r for r in reps) else None
        reasons = 0
        for r in reps:
            reasons |= int(r.get("throttle_reasons", 0) or 0)
        base.update(
            status="ok", repetitions=len(reps), times_ms=[t for t in times if t is not None], ms=ms,
            rays_per_second=med("rays_per_second"),
            samples_per_second=(spf / (ms / 1e3)) if ms else None,
            peak_host_bytes=peak("peak_host_bytes"), peak_device_bytes=peak("peak_device_bytes"),
            joules_per_frame=med("energy_joules_per_frame"), rays_per_joule=med("rays_per_joule"),
            average_watts=med("average_watts"), energy_busy_fraction=med("energy_busy_fraction"),
            energy_reason=None if med("energy_joules_per_frame") is not None else no_energy.get(c["name"]),
            sm_clock_mhz=med("sm_clock_mhz_mean"), temperature_c_max=peak("temperature_c_max"),
            throttled=throttled, throttle_reasons=reasons if throttled is not None else None,
            triangles=med("triangles"), isa=isa, film_hash=hashes.get(c["name"]),
            build_seconds=med("build_seconds"))
        out.append(base)
    return out


def mann_whitney_p(a: list[float], b: list[float]) -> float:
    """Two-sided p of the Mann-Whitney U test (normal approximation, tie-corrected)."""
    n1, n2 = len(a), len(b)
    if n1 < 2 or n2 < 2:
        return 1.0
    allv = sorted([(v, 0) for v in a] + [(v, 1) for v in b])
    ranks = [0.0] * len(allv)
    i, ties = 0, 0.0
    while i < len(allv):
        j = i
        while j + 1 < len(allv) and allv[j + 1][0] == allv[i][0]:
            j += 1
        for k in range(i, j + 1):
            ranks[k] = (i + j) / 2 + 1
        t = j - i + 1
        ties += t ** 3 - t
        i = j + 1
    r1 = sum(r for r, (_, g) in zip(ranks, allv) if g == 0)
    u = r1 - n1 * (n1 + 1) / 2
    n = n1 + n2
    var = n1 * n2 / 12 * ((n + 1) - ties / (n * (n - 1)))
    if var <= 0:
        return 1.0
    z = (abs(u - n1 * n2 / 2) - 0.5) / math.sqrt(var)
    return math.erfc(max(z, 0) / math.sqrt(2))


def verdict(now: list[float], before: list[float]) -> dict:
    """compare's rule: significant (U test) and beyond the threshold, on the time per frame."""
    m_now, m_before = _median(now), _median(before)
    if not m_now or not m_before:
        return {"verdict": "n/a"}
    change = m_now / m_before - 1
    p = mann_whitney_p(now, before)
    v = "same"
    if p < ALPHA and change > THRESHOLD:
        v = "slower"
    elif p < ALPHA and change < -THRESHOLD:
        v = "faster"
    return {"verdict": v, "change": change, "p": p, "before_ms": m_before}


def previous_runs(db_path: str, sources: list[str], preset: str) -> dict[str, dict]:
    """benchmark -> {times_ms, run_date, commit} of this machine's latest earlier run of the preset.
    `sources`: the bench JSON file names just recorded (the history's runs.source)."""
    if not os.path.exists(db_path) or not sources:
        return {}
    con = sqlite3.connect(f"file:{db_path}?mode=ro", uri=True)
    try:
        q = ",".join("?" * len(sources))
        cur = con.execute(f"SELECT id, machine_id FROM runs WHERE source IN ({q}) ORDER BY id", sources)
        mine = cur.fetchall()
        if not mine:
            return {}
        first_id, machine = min(r[0] for r in mine), mine[0][1]
        rows = con.execute(
            "SELECT r.benchmark, r.value, r.unit, runs.id, runs.run_date, runs.commit_sha FROM results r "
            "JOIN runs ON runs.id = r.run_id WHERE runs.machine_id = ? AND runs.preset = ? AND runs.id < ? "
            "ORDER BY runs.id", (machine, preset, first_id)).fetchall()
    finally:
        con.close()
    latest: dict[str, dict] = {}
    for bench, value, unit, run_id, date, commit in rows:
        if unit != "ms" or not isinstance(value, (int, float)):
            continue
        cur = latest.get(series(bench))
        if cur is None or run_id > cur["run_id"]:
            latest[series(bench)] = cur = {"run_id": run_id, "run_date": date, "commit": commit, "times_ms": []}
        if run_id == cur["run_id"]:
            cur["times_ms"].append(value)
    return latest


def reference_runs(export_dir: str, preset: str, exclude_sources=()) -> dict[str, dict]:
    """machine name -> {benchmark: {times_ms, run_date, commit}} from the text export: each
    reference machine's latest run of the preset, per benchmark. A GPU run's machine is named
    with its GPU ("intel-r-xeon-r · NVIDIA H100 80GB HBM3")."""
    refs: dict[str, dict] = {}
    for path in sorted(glob.glob(os.path.join(export_dir, "*.jsonl"))):
        try:
            with open(path) as f:
                head = json.loads(f.readline())["run"]
                if head.get("preset") != preset or head.get("source") in exclude_sources:
                    continue  # another preset, or this very run (recorded into the export just now)
                name = head.get("machine_name") or head.get("machine_id", "?")
                ctx = head.get("context") or {}
                if str(ctx.get("suite_device_label", "")).startswith("gpu") and ctx.get("gpu_name"):
                    # The machine's name is its host CPU's: a GPU run is another machine on the same
                    # host model (an H100's and an H200's hosts are both "intel-r-xeon-r").
                    name = f"{name} · {ctx['gpu_name']}"
                date = head.get("run_date", "")
                per = refs.setdefault(name, {})
                for line in f:
                    r = json.loads(line)
                    if r.get("unit") != "ms" or not isinstance(r.get("value"), (int, float)):
                        continue
                    cur = per.get(series(r["benchmark"]))
                    if cur is None or date > cur["run_date"]:
                        per[series(r["benchmark"])] = cur = {"run_date": date, "commit": head.get("commit", ""), "times_ms": [],
                                                     "counters": r.get("counters") or {}}
                    if date == cur["run_date"]:
                        cur["times_ms"].append(r["value"])
        except (OSError, ValueError, KeyError, TypeError):
            continue  # one unreadable run file does not stop the page
    return refs
