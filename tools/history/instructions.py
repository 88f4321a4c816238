"""Instruction-count benchmark: callgrind counts of the CPU strategies' render loop, written as a
bench-like JSON (Google Benchmark's layout) so `history record` stores it as its own series.

Instruction counts do not move with machine load, so CI on a shared 2-core host can see CPU
regressions that wall time hides in noise. The render is scripts/cpu_instructions.sh's at a quarter
of its pixels (so a commit measures in about a minute on a loaded host): paper-cornell 32x32, 16 spp,
2 bounces, nee, one thread, collection toggled on inside the diffuse-only float instantiation of
each strategy; per-sample figures run a little above that script's (fixed per-render costs spread
over fewer samples). This file is self-contained (standard library only) because the
backfill copies it next to old checkouts that lack it; it adapts to what the binary offers
(--embree-layout only exists from 4f72512 on).

Benchmarks written (value = instructions per sample in real_time, time_unit "instructions"):
  callgrind/paper-cornell/<strategy>/<layout>/instructions   layout: triangles, quads (when offered),
                                                             default (the one the binary picks itself)
and, with --wall N, the same render run natively N times:
  wall/paper-cornell/<strategy>/<layout>/128x128/spp:16      real_time in ms (noisy on a loaded host)
"""
from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

WIDTH, SPP = 32, 16
# Wildcards, so small signature changes across the history still match.
TOGGLE = {
    "pixel": "*render_pixel_parallel_for<float, 1u>*",
    "wavefront": "*render_wavefront_for<float, 1u>*",
}


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def _caches() -> list[dict]:
    out = []
    base = "/sys/devices/system/cpu/cpu0/cache"
    try:
        for d in sorted(os.listdir(base)):
            if not d.startswith("index"):
                continue
            def rd(name: str) -> str:
                with open(os.path.join(base, d, name)) as f:
                    return f.read().strip()
            size = rd("size")
            mult = {"K": 1024, "M": 1024 * 1024}.get(size[-1], 1)
            out.append({"type": rd("type"), "level": int(rd("level")),
                        "size": int(size.rstrip("KM")) * mult})
    except (OSError, ValueError):
        pass
    return out


def machine_context() -> dict:
    """The fields `history` keys machines by when no fingerprint object exists (see store.machine_id)."""
    mhz = 0
    try:
        with open("/proc/cpuinfo") as f:
            m = re.search(r"cpu MHz\s*:\s*([\d.]+)", f.read())
            mhz = int(float(m.group(1))) if m else 0
    except OSError:
        pass
    return {
        "host_name": platform.node(),
        "cpu_model": _cpu_model(),
        "num_cpus": os.cpu_count() or 0,
        "mhz_per_cpu": mhz,
        "caches": _caches(),
    }


def _render_args(exe: str, strategy: str, layout: str | None, width: int, spp: int, out: str) -> list[str]:
    args = [exe, "render", "--scene", "paper-cornell", "--width", str(width), "--height", str(width),
            "--spp", str(spp), "--bounces", "2", "--sampling", "nee", "--threads", "1",
            "--strategy", strategy, "--quiet", "--out", out]
    if layout is not None:
        args += ["--embree-layout", layout]
    return args


def layouts_offered(exe: str) -> list[str | None]:
    """[None] (the binary's only layout, triangles) before --embree-layout existed."""
    help_text = subprocess.run([exe, "render", "--help"], capture_output=True, text=True).stdout
    return ["triangles", "quads"] if "--embree-layout" in help_text else [None]


def default_layout(exe: str, tmp: str) -> str:
    """The layout this binary traces paper-cornell with when not told (auto measures a probe, so it is
    read from a native render's report, never under valgrind); triangles before the layouts existed."""
    if layouts_offered(exe) == [None]:
        return "triangles"
    report = os.path.join(tmp, "default.json")
    subprocess.run(_render_args(exe, "pixel", None, 32, 1, os.path.join(tmp, "default.pfm")) + ["--report", report],
                   check=True, capture_output=True)
    with open(report) as f:
        return json.load(f)["embree_layout"]["used"]


def count(exe: str, strategy: str, layout: str | None, tmp: str, width: int = WIDTH, spp: int = SPP) -> int:
    out = os.path.join(tmp, f"callgrind.out.{strategy}")
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
           f"--toggle-collect={TOGGLE[strategy]}"] + _render_args(
               exe, strategy, layout, width, spp, os.path.join(tmp, "image.pfm"))
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"callgrind run failed ({strategy}, {layout}): {r.stderr[-500:]}")
    with open(out) as f:
        m = re.search(r"^summary:\s*(\d+)", f.read(), re.M)
    if not m or int(m.group(1)) == 0:
        raise RuntimeError(f"no instructions counted inside {TOGGLE[strategy]}")
    return int(m.group(1))


def wall_ms(exe: str, strategy: str, layout: str | None, tmp: str) -> float:
    report = os.path.join(tmp, "report.json")
    args = _render_args(exe, strategy, layout, 128, 16, os.path.join(tmp, "wall.pfm")) + ["--report", report]
    t0 = time.perf_counter()
    subprocess.run(args, check=True, capture_output=True)
    try:
        with open(report) as f:
            return float(json.load(f)["seconds"]) * 1e3
    except (OSError, KeyError, ValueError):
        return (time.perf_counter() - t0) * 1e3


def _row(name: str, rep: int, reps: int, value: float, unit: str, **counters) -> dict:
    return {"name": name, "run_name": name, "run_type": "iteration", "repetitions": reps,
            "repetition_index": rep, "threads": 1, "iterations": 1, "real_time": value,
            "cpu_time": value, "time_unit": unit, **counters}


def measure(exe: str, wall_reps: int = 0, revision: str | None = None, width: int = WIDTH, spp: int = SPP) -> dict:
    now = dt.datetime.now(dt.timezone.utc)
    ctx = machine_context() | {
        "date": now.isoformat(timespec="seconds"), "executable": exe, "pathbench_preset": "instructions",
        "load_avg": list(os.getloadavg()), "valgrind": shutil.which("valgrind") and subprocess.run(
            ["valgrind", "--version"], capture_output=True, text=True).stdout.strip(),
    }
    ctx["instructions_render"] = f"paper-cornell {width}x{width} spp:{spp} bounces:2 nee threads:1"
    if revision:
        ctx["git_revision"] = revision
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        # The callgrind runs go side by side: counts do not depend on load, and on a shared host
        # four processes get more of the CPU than one does.
        tasks = [(layout, strategy) for layout in layouts_offered(exe) for strategy in ("pixel", "wavefront")]
        dirs = []
        for i in range(len(tasks)):
            dirs.append(os.path.join(tmp, str(i)))
            os.makedirs(dirs[-1])
        with ThreadPoolExecutor(max_workers=len(tasks)) as pool:
            counts = list(pool.map(lambda t: count(exe, t[1], t[0], t[2], width, spp),
                                   [t + (d,) for t, d in zip(tasks, dirs)]))
        for (layout, strategy), ir in zip(tasks, counts):
            name_layout = layout or "triangles"
            n = width * width * spp
            rows.append(_row(f"callgrind/paper-cornell/{strategy}/{name_layout}/instructions", 0, 1,
                             ir / n, "instructions", instructions=ir, samples=n))
        # The series a user gets by default: the counts of the layout the binary picks by itself.
        chosen = default_layout(exe, tmp)
        for row in list(rows):
            if f"/{chosen}/instructions" in row["name"]:
                rows.append(row | {"name": row["name"].replace(f"/{chosen}/", "/default/"),
                                   "run_name": row["run_name"].replace(f"/{chosen}/", "/default/"), "layout": chosen})
        for layout, strategy in tasks:  # timed one after another, after the counts
            name = f"wall/paper-cornell/{strategy}/{layout or 'triangles'}/128x128/spp:16"
            for rep in range(wall_reps):
                rows.append(_row(name, rep, wall_reps, wall_ms(exe, strategy, layout, tmp), "ms"))
    return {"context": ctx, "benchmarks": rows}


def main(argv: list[str] | None = None) -> int:
    class Parser(argparse.ArgumentParser):  # a usage error in one line, exit 2 (docs/history.md)
        def error(self, message):
            print(f"pathbench history instructions: error: {message}", file=sys.stderr)
            sys.exit(2)

    ap = Parser(prog="pathbench history instructions", description=__doc__.split("\n\n")[0])
    ap.add_argument("--build-dir", default="build", help="build folder holding bin/pathbench")
    ap.add_argument("--out", required=True, help="JSON file to write")
    ap.add_argument("--wall", type=int, default=0, metavar="N", help="also N native timed renders per series")
    ap.add_argument("--revision", help="git revision to write into the context")
    ap.add_argument("--width", type=int, default=WIDTH, help="image side in pixels (series differ by size)")
    ap.add_argument("--spp", type=int, default=SPP)
    a = ap.parse_args(argv)
    exe = os.path.join(a.build_dir, "bin", "pathbench")
    if not os.access(exe, os.X_OK):
        print(f"instructions: {exe}: not an executable pathbench", file=sys.stderr)
        return 2
    if shutil.which("valgrind") is None:
        print("instructions: valgrind not found on PATH", file=sys.stderr)
        return 2
    data = measure(exe, a.wall, a.revision, a.width, a.spp)
    tmp = a.out + ".tmp"
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1, allow_nan=False)
        f.write("\n")
    os.replace(tmp, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
