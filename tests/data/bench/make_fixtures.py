#!/usr/bin/env python3
"""Writes the synthetic Google Benchmark JSON fixtures for `pathbench compare`'s tests
(tests/bench/test_compare.cpp). Deterministic: `python3 make_fixtures.py` in this
folder rewrites the same files. quick-9rep.json is a real run, not made here:
  build/bin/pathbench-bench --preset quick --benchmark_repetitions=9 \
      --benchmark_report_aggregates_only=false --benchmark_out=quick-9rep.json
"""
import copy
import json
import random
import statistics

CONTEXT = {"date": "2026-11-22T00:00:00+00:00", "host_name": "fixture", "executable": "pathbench-bench",
           "num_cpus": 2, "mhz_per_cpu": 2445, "cpu_scaling_enabled": False,
           "caches": [{"type": "Unified", "level": 2, "size": 524288}],
           "load_avg": [0.0, 0.0, 0.0], "library_build_type": "release", "pathbench_preset": "fixture"}
BENCHES = [("render/cpu/pixel/paper-cornell/64x64/spp:4/bounces:2/nee/manual_time", 12.0, 5.7e6),
           ("render/cpu/wavefront/paper-cornell/64x64/spp:4/bounces:2/nee/manual_time", 10.0, 6.5e6),
           ("raycast/cpu/intersect16/incoherent/paper-cornell/real_time", 1.6, 1.0e7)]


def doc(times_by_bench, reps, layout="quads", names=None):
    out = {"context": copy.deepcopy(CONTEXT), "benchmarks": []}
    for (name, _, rays_ms), times in zip(BENCHES, times_by_bench):
        name = names(name) if names else name
        for i, t in enumerate(times[:reps]):
            out["benchmarks"].append({
                "name": name, "family_index": 0, "per_family_instance_index": 0, "run_name": name,
                "run_type": "iteration", "repetitions": reps, "repetition_index": i, "threads": 1,
                "iterations": 10, "real_time": t, "cpu_time": t / 2, "time_unit": "ms",
                "rays_per_second": rays_ms * BENCHES[0][1] / t if t else 0.0, "label": f"embree_layout={layout}"})
        for agg, f in (("median", statistics.median), ("mean", statistics.mean)):
            out["benchmarks"].append({
                "name": f"{name}_{agg}", "run_name": name, "run_type": "aggregate", "repetitions": reps,
                "threads": 1, "aggregate_name": agg, "iterations": reps, "real_time": f(times[:reps]),
                "cpu_time": f(times[:reps]) / 2, "time_unit": "ms"})
    return out


def write(name, d):
    with open(name, "w") as f:
        json.dump(d, f, indent=2)
        f.write("\n")


def main():
    rng = random.Random(20261122)
    base = [[m * (1 + rng.gauss(0, 0.01)) for _ in range(9)] for _, m, _ in BENCHES]
    write("base.json", doc(base, 9))
    # Same values, repetitions in another order.
    write("identical.json", doc([list(reversed(t)) for t in base], 9))
    # Every repetition 10% slower: must be judged a regression.
    write("slower10.json", doc([[x * 1.10 for x in t] for t in base], 9))
    # Noisy but equal: two independent draws with a 15% coefficient of variation
    # from the same distribution; must not be judged a regression.
    noisy = random.Random(7)
    write("noisy-a.json", doc([[m * (1 + noisy.gauss(0, 0.15)) for _ in range(9)] for _, m, _ in BENCHES], 9))
    write("noisy-b.json", doc([[m * (1 + noisy.gauss(0, 0.15)) for _ in range(9)] for _, m, _ in BENCHES], 9))
    # Bad input.
    write("too-few-repetitions.json", doc(base, 3))
    aggregates_only = doc(base, 9)
    aggregates_only["benchmarks"] = [b for b in aggregates_only["benchmarks"] if b["run_type"] == "aggregate"]
    write("aggregates-only.json", aggregates_only)
    write("not-benchmark.json", {"scene": "paper-cornell", "seconds": 12.5})
    # compare's context checks (same times as base, one thing different each):
    # no benchmark name in common; every time zero (a broken run, not "-100%");
    # Embree traced triangles instead of quads; and another host that Google Benchmark
    # also calls 2 CPUs "AMD EPYC" (the example: 2596 MHz, 1 MiB L2).
    write("other-names.json", doc(base, 9, names=lambda n: n.replace("paper-cornell", "cornell-box")))
    write("zero-times.json", doc([[0.0] * 9 for _ in BENCHES], 9))
    write("layout-triangles.json", doc(base, 9, layout="triangles"))
    other = doc(base, 9)
    other["context"].update({"mhz_per_cpu": 2596, "caches": [{"type": "Unified", "level": 2, "size": 1048576}]})
    write("other-machine.json", other)


if __name__ == "__main__":
    main()
