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
calls (the benchmarks' 16-wide ones: the wavefront's own width with `--isa avx512`; its
8-wide packets with avx2 or scalar ran the same kernel on an AVX2 host's Embree,
docs/notes/cpu-log.md).

Run on its own, it sets render reports against the raw rates, one line per report with
the instruction set its path step ran (`--isa`, the report's `isa`) and the CPU's flags:

    build/bin/pathbench render --strategy wavefront --isa avx2 --report wf-avx2.json ...
    .venv/bin/python tools/raw_embree_mix.py wf-avx2.json wf-avx512.json [--out shares.json]
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
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


def measure(bench_binary: str | Path, preset: str = "paper", context: dict | None = None) -> dict[str, float]:
    """Runs the raycast benchmarks once; returns rays/s by benchmark name. `context`, when
    given, is updated with the run's Google Benchmark context (its fingerprint names the
    Embree device: version, native packet widths)."""
    names = sorted({bench_name(k, w) for k in KINDS for w in WIDTH.values()})
    pattern = "^(" + "|".join(n.replace("/real_time", "") for n in names) + ")"
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "raycast.json"
        subprocess.run([str(bench_binary), "--preset", preset, f"--benchmark_filter={pattern}",
                        f"--benchmark_out={out}", "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL)
        data = json.loads(out.read_text())
        runs = data["benchmarks"]
        if context is not None:
            context.update(data.get("context", {}))
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


def shares(reports: list[dict], rates: dict[str, float]) -> list[dict]:
    """Each report's rays/s over the raw rate of its own ray mix, with its strategy and ISA."""
    out = []
    for r in reports:
        raw = mix_rate(r["rays"], rates, r["strategy"])
        out.append({"strategy": r["strategy"], "isa": r.get("isa"), "isa_asked": r.get("isa_asked"),
                    "watertight": r.get("watertight"), "rays_per_second": r["rays_per_second"],
                    "raw_rays_per_second": round(raw), "share": round(r["rays_per_second"] / raw, 4)})
    return out


def main(argv=None) -> int:
    from machine import cpu_model, cpu_vector_flags  # tools/ is on sys.path when run as a script

    root = Path(__file__).resolve().parent.parent
    ap = argparse.ArgumentParser(description="share of Embree's raw ray-cast rate, per render report")
    ap.add_argument("reports", nargs="+", help="pathbench render --report JSON files (paper-cornell, cpu)")
    ap.add_argument("--bench", default=str(root / "build" / "bin" / "pathbench-bench"))
    ap.add_argument("--rounds", type=int, default=3, help="raw benchmark runs (median)")
    ap.add_argument("--out", help="write the result as JSON here")
    a = ap.parse_args(argv)
    reports = []
    for f in a.reports:
        try:
            r = json.loads(Path(f).read_text())
        except (OSError, json.JSONDecodeError) as e:
            print(f"{f}: cannot read the report: {e}", file=sys.stderr)
            return 2
        if r.get("scene") != SCENE or r.get("device") != "cpu" or r.get("strategy") not in WIDTH:
            print(f"{f}: not a CPU pixel/wavefront render of {SCENE} (the raw rates are for that scene)", file=sys.stderr)
            return 2
        reports.append(r)
    if not Path(a.bench).is_file():
        print(f"{a.bench}: not built (scripts/build.sh, or pass --bench)", file=sys.stderr)
        return 2
    rates = median_rates([measure(a.bench) for _ in range(a.rounds)])
    res = {"cpu": cpu_model(), "cpu_flags": cpu_vector_flags(), "raw_rates": rates, "shares": shares(reports, rates)}
    for f, s in zip(a.reports, res["shares"]):
        print(f"{f}: {s['strategy']} isa={s['isa']}: {s['rays_per_second'] / 1e6:.1f} M rays/s, raw "
              f"{s['raw_rays_per_second'] / 1e6:.1f} M for its mix: {100 * s['share']:.0f}%")
    print("CPU flags: " + " ".join(res["cpu_flags"]))
    if a.out:
        Path(a.out).write_text(json.dumps(res, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
