#!/usr/bin/env python3
"""The suite's bench JSON again from the history database `pathbench suite` recorded it into on
the GPU host (2026-11-27, call at 2cae000): that call's bench JSON did not come back (its
tarball was over the device tool's 16 MiB a file), its two databases did. Every figure is the
database's (per repetition: time, CPU time, iterations, rays/s, every counter; the run's
context with its film hashes and fingerprint); Google Benchmark's aggregates and the
per-benchmark label (the CPU's ISA) are not stored there and are not made up.
    rebuild_bench_json.py DB OUT_DIR   -> OUT_DIR/<the run's source name> per run"""
import json
import os
import sqlite3
import sys

db, out = sys.argv[1], sys.argv[2]
con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
for run_id, source, context in con.execute("SELECT id, source, context FROM runs ORDER BY id"):
    ctx = json.loads(context)
    ctx["rebuilt_from_history_db"] = ("bench JSON rebuilt from the device run's history database "
                                      "(results/suite/README.md): no aggregates, no labels")
    rows = con.execute("SELECT benchmark, repetition, value, unit, cpu_time, iterations, rays_per_second, counters "
                       "FROM results WHERE run_id = ? ORDER BY benchmark, repetition", (run_id,)).fetchall()
    reps = {}
    for r in rows:
        reps[r[0]] = reps.get(r[0], 0) + 1
    benchmarks = []
    for bench, rep, value, unit, cpu_time, iterations, rays, counters in rows:
        b = {"name": bench, "family_index": 0, "per_family_instance_index": 0, "run_name": bench,
             "run_type": "iteration", "repetitions": reps[bench], "repetition_index": rep, "threads": 1,
             "iterations": iterations, "real_time": value, "cpu_time": cpu_time, "time_unit": unit}
        b.update(json.loads(counters) if counters else {})
        if rays is not None:
            b["rays_per_second"] = rays
        benchmarks.append(b)
    with open(os.path.join(out, source), "w") as f:
        json.dump({"context": ctx, "benchmarks": benchmarks}, f, indent=1, allow_nan=False)
        f.write("\n")
    print(source, len(benchmarks))
