"""Embree's raw ray-cast rate for the ray mix of a render (issue 2: how close each CPU
strategy comes to it).

pathbench-bench's raycast benchmarks cast prepared rays on paper-cornell with nothing
else to do: camera rays (coherent) and their diffuse bounces (incoherent), as closest
hits and as occlusion rays that stop just short of the hit (as unoccluded shadow rays
do). A render's own mix is taken from its report (rays by kind): camera rays as
coherent closest hits, bounce rays as incoherent closest hits, shadow rays as incoherent
occlusion rays. The mix's raw rate is the harmonic mix of the three:

    raw = total / (camera / r_camera + bounce / r_bounce + shadow / r_shadow)

and a strategy's share is its rays/s over that. The pixel strategy is compared with
Embree's single-ray calls (rtcIntersect1 / rtcOccluded1), the wavefront with its packet
calls (the benchmarks' 16-wide ones; the CPU's 8-wide packets run the same kernel on
this Embree, notes/cpu-performance.md).
"""
from __future__ import annotations

import json
import statistics
import subprocess
import tempfile
from pathlib import Path

SCENE = "paper-cornell"
# (ray kind in a render report) -> (benchmark api suffix, coherence)
KINDS = {"camera": ("intersect", "coherent"), "bounce": ("intersect", "incoherent"),
         "shadow": ("occluded", "incoherent")}
WIDTH = {"pixel": "1", "wavefront": "16"}  # Embree call width compared with each strategy


def bench_name(kind: str, width: str) -> str:
    api, coherence = KINDS[kind]
    return f"raycast/cpu/{api}{width}/{coherence}/{SCENE}/real_time"


def measure(bench_binary: str | Path, preset: str = "paper") -> dict[str, float]:
    """Runs the raycast benchmarks once; returns rays/s by benchmark name."""
    names = sorted({bench_name(k, w) for k in KINDS for w in WIDTH.values()})
    pattern = "^(" + "|".join(n.replace("/real_time", "") for n in names) + ")"
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "raycast.json"
        subprocess.run([str(bench_binary), "--preset", preset, f"--benchmark_filter={pattern}",
                        f"--benchmark_out={out}", "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL)
        runs = json.loads(out.read_text())["benchmarks"]
    rates = {b["name"]: float(b["rays_per_second"]) for b in runs if b["name"] in names}
    missing = set(names) - set(rates)
    if missing:
        raise RuntimeError(f"{bench_binary}: no result for {sorted(missing)}")
    return rates


def median_rates(rounds: list[dict[str, float]]) -> dict[str, float]:
    return {n: statistics.median(r[n] for r in rounds) for n in rounds[0]}


def mix_rate(rays: dict[str, int], rates: dict[str, float], strategy: str) -> float:
    """Raw rays/s for `rays` (a report's rays by kind) with the calls matching `strategy`."""
    width = WIDTH[strategy]
    seconds = sum(rays[k] / rates[bench_name(k, width)] for k in KINDS)
    return sum(rays[k] for k in KINDS) / seconds
