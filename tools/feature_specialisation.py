#!/usr/bin/env python3
"""Feature specialisation check: does a diffuse-only scene pay for the other materials?

paper-cornell (diffuse only) rendered by a normal build (every material kind compiled
in; the render runs the path step's diffuse-only instantiation, features.h) against a
build configured with -DPATHBENCH_EXTRA_MATERIALS=OFF (no other kind exists at all).
The normal build must be at most 3 % slower.

    .venv/bin/python tools/feature_specialisation.py --method callgrind   # loaded machine
    .venv/bin/python tools/feature_specialisation.py --method wallclock   # quiet machine

Both builds are configured and built here (build-feature-on/, build-feature-off/;
CUDA off, targets pathbench and pathbench-bench) unless --on-build / --off-build name
existing ones. Methods:
  callgrind  instructions executed by the render itself (callgrind, collection toggled
             on inside the diffuse-only instantiation pb::cpu::render_pixel_parallel_for
             <float, 1u> / render_wavefront_for<float, 1u>, one thread), exact and
             insensitive to other load: the right measure on a shared machine.
  wallclock  pathbench-bench --preset materials, the paper-cornell CPU rows, the two
             builds interleaved for --rounds rounds of --repetitions each; the ratio of
             median rays/s. Run it on a quiet machine (load average is recorded).
Writes (adds its method to) results/<machine>/feature-specialisation.{json,md}.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import cpu_model, host_fingerprint, machine_slug  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
MAX_SLOWDOWN = 0.03
STRATEGIES = ("pixel", "wavefront")
# The diffuse-only instantiations' entry points, by their full demangled names (a
# trailing * would also match their lambdas and toggle collection off inside them).
TOGGLE = {"pixel": "pb::cpu::TraceTotals pb::cpu::render_pixel_parallel_for<float, 1u>(pb::cpu::TraceJob const&)",
          "wavefront": "pb::cpu::TraceTotals pb::cpu::render_wavefront_for<float, 1u>(pb::cpu::TraceJob const&, "
                       "unsigned long)"}


def git_revision():
    try:
        return subprocess.run(["git", "describe", "--always", "--dirty", "--abbrev=12"], cwd=ROOT, check=True,
                              capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def build(build_dir: Path, extra_materials: bool, jobs: int):
    flag = "ON" if extra_materials else "OFF"
    subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                    "-DPATHBENCH_CUDA=OFF", "-DPATHBENCH_TESTS=OFF", f"-DPATHBENCH_EXTRA_MATERIALS={flag}"],
                   check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", str(build_dir), "-j", str(jobs), "--target", "pathbench", "pathbench-bench"],
                   check=True)
    cache = (build_dir / "CMakeCache.txt").read_text()
    if f"PATHBENCH_EXTRA_MATERIALS:BOOL={flag}" not in cache:
        raise SystemExit(f"{build_dir}: PATHBENCH_EXTRA_MATERIALS is not {flag} in its CMakeCache.txt")


def render_args(a, strategy):
    return ["render", "--scene", "paper-cornell", "--width", str(a.size), "--height", str(a.size), "--spp", str(a.spp),
            "--bounces", "2", "--sampling", "nee", "--strategy", strategy, "--threads", "1", "--quiet",
            # Pinned: `auto` times a probe in each process (and under valgrind its timing means
            # little), and the two builds must trace the same layout. Quads: what auto picks for
            # paper-cornell when it runs at full speed (results/amd-epyc/mitsuba-vs-pathbench.md).
            "--embree-layout", "quads"]


def callgrind_instructions(binary: Path, a, strategy: str) -> int:
    """Instructions (Ir) executed inside the strategy's render function."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", f"--toggle-collect={TOGGLE[strategy]}",
               str(binary)] + render_args(a, strategy) + ["--out", str(Path(tmp) / "image.pfm")]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        text = out.read_text()
    m = re.search(r"^(?:summary|totals):\s+(\d+)", text, re.M)
    if not m:
        raise SystemExit(f"no instruction total in callgrind output of {binary}")
    return int(m.group(1))


def image_bytes(binary: Path, a, strategy: str) -> bytes:
    with tempfile.TemporaryDirectory() as tmp:
        img = Path(tmp) / "image.pfm"
        subprocess.run([str(binary)] + render_args(a, strategy) + ["--out", str(img)], check=True)
        return img.read_bytes()


def wallclock_rays_per_second(bench: Path, a, strategy: str) -> list[float]:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.json"
        subprocess.run([str(bench), "--preset", "materials",
                        f"--benchmark_filter=^render/cpu/{strategy}/paper-cornell/",
                        f"--benchmark_repetitions={a.repetitions}", "--benchmark_report_aggregates_only=false",
                        f"--benchmark_out={out}", "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL)
        data = json.loads(out.read_text())
    return [b["rays_per_second"] for b in data["benchmarks"] if b.get("run_type") == "iteration"]


def markdown(doc) -> str:
    lines = ["# Feature specialisation: paper-cornell, every material kind compiled in vs a diffuse-only build", "",
             "The normal build renders a diffuse-only scene with the path step's diffuse-only instantiation; the",
             "diffuse-only build (-DPATHBENCH_EXTRA_MATERIALS=OFF) has no other material kind at all. Limit: the",
             "normal build at most 3 % slower. Made by tools/feature_specialisation.py.", ""]
    for method, res in doc["methods"].items():
        lines += [f"## {method}", "",
                  f"{res['measure']}. Render: {res['render']}. Machine: {res['machine']}. Commit: "
                  f"{res['git_revision']}. Load average before / after: {res['load_average_before']} / "
                  f"{res['load_average_after']}.", "",
                  "| strategy | normal build | diffuse-only build | normal / diffuse-only | normal slower by | within 3 % |",
                  "|---|---|---|---|---|---|"]
        for s, r in res["strategies"].items():
            lines.append(f"| {s} | {r['normal']:,.0f} | {r['diffuse_only']:,.0f} | {r['ratio']:.4f} | "
                         f"{100 * r['slowdown']:+.2f} % | {'yes' if r['within_limit'] else 'NO'} |")
        lines += ["", res["note"], ""]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--method", choices=["callgrind", "wallclock"], default="callgrind")
    ap.add_argument("--on-build", type=Path, help="an existing normal build (default: build it)")
    ap.add_argument("--off-build", type=Path, help="an existing -DPATHBENCH_EXTRA_MATERIALS=OFF build")
    ap.add_argument("--jobs", type=int, default=2, help="build parallelism")
    ap.add_argument("--size", type=int, default=64, help="callgrind: image side")
    ap.add_argument("--spp", type=int, default=4, help="callgrind: samples per pixel")
    ap.add_argument("--rounds", type=int, default=3, help="wallclock: interleaved rounds")
    ap.add_argument("--repetitions", type=int, default=9, help="wallclock: benchmark repetitions per round")
    ap.add_argument("--out-dir", type=Path, default=ROOT / "results" / machine_slug())
    a = ap.parse_args(argv)

    on = a.on_build or ROOT / "build-feature-on"
    off = a.off_build or ROOT / "build-feature-off"
    if not a.on_build:
        build(on, True, a.jobs)
    if not a.off_build:
        build(off, False, a.jobs)

    res = {"method": a.method, "machine": cpu_model(), "fingerprint": host_fingerprint(), "git_revision": git_revision(),
           "load_average_before": [round(x, 2) for x in os.getloadavg()], "max_slowdown": MAX_SLOWDOWN,
           "builds": {"normal": str(on), "diffuse_only": str(off)}, "strategies": {}}
    for strategy in STRATEGIES:
        if a.method == "callgrind":
            res["measure"] = "instructions executed in the render, lower is faster"
            res["render"] = f"{a.size}x{a.size}, {a.spp} spp, 2 bounces, nee, 1 thread"
            # Same image from both builds: the comparison is of the same work.
            if image_bytes(on / "bin" / "pathbench", a, strategy) != image_bytes(off / "bin" / "pathbench", a, strategy):
                raise SystemExit(f"{strategy}: the two builds render different images")
            normal = callgrind_instructions(on / "bin" / "pathbench", a, strategy)
            diffuse = callgrind_instructions(off / "bin" / "pathbench", a, strategy)
            slowdown = normal / diffuse - 1
            r = {"normal": normal, "diffuse_only": diffuse, "ratio": normal / diffuse}
        else:
            res["measure"] = "median rays/s over all repetitions, higher is faster"
            res["render"] = "pathbench-bench --preset materials: 128x128, 16 spp, 4 bounces, nee, all threads"
            runs_on, runs_off = [], []
            for _ in range(a.rounds):  # interleaved, so drifting load hits both builds
                runs_on += wallclock_rays_per_second(on / "bin" / "pathbench-bench", a, strategy)
                runs_off += wallclock_rays_per_second(off / "bin" / "pathbench-bench", a, strategy)
            normal, diffuse = statistics.median(runs_on), statistics.median(runs_off)
            slowdown = diffuse / normal - 1
            r = {"normal": normal, "diffuse_only": diffuse, "ratio": normal / diffuse,
                 "normal_runs": runs_on, "diffuse_only_runs": runs_off}
        r["slowdown"] = slowdown
        r["within_limit"] = slowdown <= MAX_SLOWDOWN
        res["strategies"][strategy] = r
        print(f"{strategy}: normal {normal:,.0f}, diffuse-only {diffuse:,.0f}, slower by {100 * slowdown:+.2f} %",
              flush=True)
    res["load_average_after"] = [round(x, 2) for x in os.getloadavg()]
    res["note"] = ("'normal slower by' is instructions normal / diffuse-only - 1 (callgrind) or rays/s "
                   "diffuse-only / normal - 1 (wall clock).")
    # One file for both methods: the callgrind count from a loaded machine and the wall
    # clock from a quiet one sit side by side.
    a.out_dir.mkdir(parents=True, exist_ok=True)
    path = a.out_dir / "feature-specialisation.json"
    doc = json.loads(path.read_text()) if path.exists() else {}
    doc.setdefault("methods", {})[a.method] = res
    path.write_text(json.dumps(doc, indent=2) + "\n")
    (a.out_dir / "feature-specialisation.md").write_text(markdown(doc))
    print(markdown(doc))
    return 0 if all(r["within_limit"] for r in res["strategies"].values()) else 1


if __name__ == "__main__":
    sys.exit(main())
