"""Synthetic histories made from a real bench JSON, for the change-point acceptance test and the
false-positive measurement: `runs` commits in a row, each run's repetitions scaled by a run-level
factor (machine drift) and a per-repetition factor (noise), and optionally a step at one commit
on some benchmarks."""
from __future__ import annotations

import copy
import datetime as dt
import json
import os
import random


def fake_commit(i: int, salt: str = "") -> str:
    import hashlib
    return hashlib.sha1(f"synthetic-{salt}-{i}".encode()).hexdigest()


def write_history(template: str, out_dir: str, runs: int, noise: float, seed: int,
                  step_at: int | None = None, step: float = 0.10, stepped=lambda name: False,
                  host: str = "synthetic-host") -> list[str]:
    """Writes runs JSON files (oldest first) and returns their paths; run i is at commit fake_commit(i)."""
    with open(template) as f:
        base = json.load(f, parse_constant=lambda c: None)
    rng = random.Random(seed)
    start = dt.datetime(2026, 1, 1, tzinfo=dt.timezone.utc)
    os.makedirs(out_dir, exist_ok=True)
    paths = []
    for i in range(runs):
        data = copy.deepcopy(base)
        ctx = data["context"]
        ctx["host_name"] = host
        ctx["git_revision"] = fake_commit(i, host)
        ctx["date"] = (start + dt.timedelta(hours=i)).isoformat()
        ctx["commit_date"] = ctx["date"]
        drift = {}
        rows = []
        for row in data["benchmarks"]:
            if row.get("run_type") != "iteration":
                continue
            name = row["run_name"]
            if name not in drift:
                drift[name] = rng.gauss(1.0, noise)
            factor = drift[name] * rng.gauss(1.0, noise / 2)
            if step_at is not None and i >= step_at and stepped(name):
                factor *= 1.0 + step
            row["real_time"] *= factor
            row["cpu_time"] *= factor
            if row.get("rays_per_second"):
                row["rays_per_second"] /= factor
            rows.append(row)
        data["benchmarks"] = rows
        path = os.path.join(out_dir, f"run-{host}-{i:03d}.json")
        with open(path, "w") as f:
            json.dump(data, f)
        paths.append(path)
    return paths
