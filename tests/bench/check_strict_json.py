#!/usr/bin/env python3
"""Every JSON pathbench writes must be strict JSON: parsed with
json.load(..., parse_constant=<refuse>) and no duplicate keys. Runs the binaries on tiny
settings and checks each output: a render report, `pathbench reproduce --spp 1` (its
report array), `pathbench-bench` (one benchmark, --benchmark_out), and
`pathbench compare --format json` on two of those runs, and `pathbench-bench
--benchmark_format=json` on stdout. Each must carry the machine fingerprint where it
describes a run, and each run its film hash (the history's image checksum): the same for
the pixel and wavefront strategies (their films are bit-identical), different for
another spp. Standard library only.

  check_strict_json.py --pathbench build/bin/pathbench --bench build/bin/pathbench-bench --out-dir DIR
"""
import argparse
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_bench_json import StrictJSONError, strict_loads  # noqa: E402


def run(cmd):
    print(" ".join(cmd), flush=True)
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode not in (0, 1):
        raise SystemExit(f"FAIL: exit {r.returncode}: {' '.join(cmd)}\n{r.stderr}")
    return r.stdout


def check_text(name, text, errors, fingerprint_at=None):
    try:
        doc = strict_loads(text)
    except (StrictJSONError, ValueError) as e:
        errors.append(f"{name}: not strict JSON: {e}")
        return None
    if fingerprint_at is not None:
        for obj in fingerprint_at(doc):
            fp = obj.get("fingerprint") if isinstance(obj, dict) else None
            if not isinstance(fp, dict) or len(fp.get("machine_id", "")) != 16:
                errors.append(f"{name}: no fingerprint with a machine_id")
    return doc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pathbench", required=True)
    ap.add_argument("--bench", required=True)
    ap.add_argument("--out-dir", required=True)
    a = ap.parse_args()
    os.makedirs(a.out_dir, exist_ok=True)
    d = a.out_dir
    errors = []

    report = os.path.join(d, "render-report.json")
    run([a.pathbench, "render", "--scene", "paper-cornell", "--width", "16", "--height", "16", "--spp", "1",
         "--quiet", "--report", report])
    with open(report) as f:
        doc = check_text("render report", f.read(), errors, lambda j: [j])
    if doc is not None and not isinstance(doc.get("load"), dict):
        errors.append("render report: no 'load' object")
    hashes = {}
    for strategy, spp in (("pixel", 1), ("wavefront", 1), ("pixel", 2)):
        path = os.path.join(d, f"render-{strategy}-{spp}.json")
        run([a.pathbench, "render", "--scene", "paper-cornell", "--width", "16", "--height", "16", "--spp", str(spp),
             "--strategy", strategy, "--quiet", "--report", path])
        with open(path) as f:
            hashes[(strategy, spp)] = (check_text(f"render report {strategy}", f.read(), errors) or {}).get("film_hash")
    if not all(isinstance(h, str) and h.startswith("fnv1a64:") and len(h) == 24 for h in hashes.values()):
        errors.append(f"render report: film_hash missing or malformed: {hashes}")
    elif hashes[("pixel", 1)] != hashes[("wavefront", 1)] or hashes[("pixel", 1)] == hashes[("pixel", 2)]:
        errors.append(f"render report: film_hash does not follow the image: {hashes}")

    rdir = os.path.join(d, "reproduce")
    run([a.pathbench, "reproduce", "--device", "cpu", "--spp", "1", "--quiet", "--out-dir", rdir])
    with open(os.path.join(rdir, "paper-cornell-report.json")) as f:
        check_text("reproduce report", f.read(), errors, lambda j: j)

    runs = []
    for i in range(2):
        out = os.path.join(d, f"bench-{i}.json")
        run([a.bench, "--preset", "quick", "--benchmark_filter=render/cpu/pixel/paper-cornell/64x64/spp:4/bounces:2/nee",
             "--benchmark_repetitions=2", "--benchmark_report_aggregates_only=false", "--benchmark_min_time=0.01",
             f"--benchmark_out={out}"])
        with open(out) as f:
            doc = check_text(f"bench run {i}", f.read(), errors, lambda j: [j["context"]])
        if doc is not None and not str(doc["context"].get("film_hash", "")).startswith("fnv1a64:"):
            errors.append(f"bench run {i}: no context.film_hash")
        runs.append(out)

    # Google Benchmark's own JSON reporter on stdout writes NaN for an always-zero
    # counter's cv; pathbench-bench prints it strict, with the same context.
    text = run([a.bench, "--preset", "quick", "--benchmark_filter=render/cpu/pixel/paper-cornell/64x64/spp:4/bounces:2/nee",
                "--benchmark_repetitions=2", "--benchmark_min_time=0.01", "--benchmark_format=json"])
    doc = check_text("bench JSON on stdout", text, errors, lambda j: [j["context"]])
    if doc is not None and (not doc.get("benchmarks") or not doc["context"].get("film_hashes")):
        errors.append("bench JSON on stdout: no benchmarks or no film_hashes")

    text = run([a.pathbench, "compare", runs[0], runs[1], "--min-repetitions", "2", "--format", "json"])
    doc = check_text("compare --format json", text, errors)
    if doc is not None and not doc.get("benchmarks"):
        errors.append("compare --format json: no benchmarks")

    for e in errors:
        print("FAIL:", e, file=sys.stderr)
    print("strict JSON:", "OK" if not errors else f"{len(errors)} problem(s)")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
