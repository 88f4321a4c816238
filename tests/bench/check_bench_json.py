#!/usr/bin/env python3
"""CI smoke check of pathbench-bench: runs `--preset quick` (short min time) into a
JSON file and asserts that it is strict JSON (no NaN/Infinity, no duplicate keys),
that the CPU pixel and wavefront render rows carry every counter, that ray-cast rows
carry rays_per_second, and that the context names the environment and carries the
machine fingerprint. Never asserts a speed. Standard library only.

  check_bench_json.py --bench build/bin/pathbench-bench --out /tmp/quick.json
  check_bench_json.py --json existing.json      (check a file without running)
"""
import argparse
import json
import subprocess
import sys

RENDER_COUNTERS = ["rays_per_second", "paths_per_second", "peak_host_bytes", "peak_device_bytes",
                   "state_bytes_per_path", "queue_bytes"]
CONTEXT_KEYS = ["cpu_model", "cpu_hardware_threads", "compiler", "cxx_flags", "git_revision", "date_utc",
                "machine_id", "fingerprint", "load_average_at_start", "load_average_at_end", "run"]
FINGERPRINT_KEYS = ["machine_id", "cpu", "memory_bytes", "clock", "os", "build", "libraries", "embree"]


class StrictJSONError(ValueError):
    pass


def _no_duplicates(pairs):
    seen = {}
    for k, v in pairs:
        if k in seen:
            raise StrictJSONError(f"duplicate key {k!r}")
        seen[k] = v
    return seen


def _no_constant(c):
    raise StrictJSONError(f"non-standard constant {c}")


def strict_loads(text):
    """json.loads that refuses NaN/Infinity and duplicate keys (what strict parsers do)."""
    return json.loads(text, object_pairs_hook=_no_duplicates, parse_constant=_no_constant)


def check(doc):
    errors = []
    ctx = doc.get("context", {})
    for k in CONTEXT_KEYS:
        if k not in ctx:
            errors.append(f"context lacks '{k}'")
    fp = ctx.get("fingerprint", {})
    for k in FINGERPRINT_KEYS:
        if not isinstance(fp, dict) or k not in fp:
            errors.append(f"context.fingerprint lacks '{k}'")
    if isinstance(fp, dict) and fp.get("machine_id") != ctx.get("machine_id"):
        errors.append("context.machine_id is not the fingerprint's")
    runs = [b for b in doc.get("benchmarks", []) if b.get("run_type", "iteration") == "iteration"]
    for strategy in ("pixel", "wavefront"):
        rows = [b for b in runs if b["name"].startswith(f"render/cpu/{strategy}/")]
        if not rows:
            errors.append(f"no render/cpu/{strategy}/ rows")
        for b in rows:
            if b.get("error_occurred"):
                errors.append(f"{b['name']}: error: {b.get('error_message')}")
                continue
            for c in RENDER_COUNTERS:
                if c not in b:
                    errors.append(f"{b['name']}: counter '{c}' missing")
                elif not isinstance(b[c], (int, float)) or b[c] < 0:
                    errors.append(f"{b['name']}: counter '{c}' = {b[c]!r}")
            if b.get("rays_per_second", 0) <= 0 or b.get("paths_per_second", 0) <= 0:
                errors.append(f"{b['name']}: no rays or paths counted")
            if strategy == "pixel" and b.get("queue_bytes", -1) != 0:
                errors.append(f"{b['name']}: pixel-parallel has no queue, queue_bytes should be 0")
    raycast = [b for b in runs if b["name"].startswith("raycast/cpu/")]
    if not raycast:
        errors.append("no raycast/cpu/ rows")
    for b in raycast:
        if not b.get("error_occurred") and b.get("rays_per_second", 0) <= 0:
            errors.append(f"{b['name']}: rays_per_second missing or zero")
    return errors


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", help="pathbench-bench binary to run with --preset quick")
    ap.add_argument("--out", help="where the run writes its JSON")
    ap.add_argument("--json", help="check this file instead of running")
    a = ap.parse_args()
    path = a.json
    if not path:
        if not (a.bench and a.out):
            ap.error("give --bench and --out, or --json")
        cmd = [a.bench, "--preset", "quick", "--benchmark_min_time=0.01", f"--benchmark_out={a.out}",
               "--benchmark_out_format=json"]
        print(" ".join(cmd), flush=True)
        r = subprocess.run(cmd)
        if r.returncode != 0:
            print(f"pathbench-bench exited with {r.returncode}", file=sys.stderr)
            return 1
        path = a.out
    with open(path) as f:
        text = f.read()
    try:
        doc = strict_loads(text)
    except (StrictJSONError, ValueError) as e:
        print(f"FAIL: {path} is not strict JSON: {e}", file=sys.stderr)
        return 1
    errors = check(doc)
    for e in errors:
        print("FAIL:", e, file=sys.stderr)
    n = len(doc.get("benchmarks", []))
    print(f"{path}: {n} benchmark rows, {'OK' if not errors else f'{len(errors)} problem(s)'}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
