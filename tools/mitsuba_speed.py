#!/usr/bin/env python3
"""Speed of pathbench's CPU tracer against Mitsuba 3 on the paper's scene, on this
machine, back to back in one run (interleaved rounds). Re-run after any change to the CPU tracer:

    .venv/bin/python tools/mitsuba_speed.py          # needs build/bin/pathbench (scripts/build.sh)

Both render paper-cornell at 256 x 256, 800 spp, two bounces (Mitsuba: `path`,
max_depth = 3; pathbench: --bounces 2 --sampling nee), box filter, all hardware
threads. Mitsuba 3 runs its llvm_ad_rgb variant (needs libLLVM: apt-get install
libllvm19); one warm-up render (JIT compilation) is excluded. The runs go in --rounds
interleaved rounds (default 5): in each, --mitsuba-per-round Mitsuba renders (default 2,
so 10 in all) bracket one `pathbench render ... --strategy pixel|wavefront --report` per
strategy (its own reported seconds), so load that comes and goes is shared out evenly.
Every timing is reported as its median with min-max and IQR; the speed-up over Mitsuba
is the ratio of the medians, with its range over the rounds (each round's Mitsuba median
over its pathbench time). The load averages and CPU count are recorded before and after
every render. With `--isa avx512,avx2,...` each strategy runs once per instruction set of
the batched path step (`pathbench render --isa`), so one run compares them on this host.

Mitsuba does not count rays. Its rays per second are an ESTIMATE: its samples per
second times pathbench's measured rays per sample for the same estimator (camera ray,
then at each of the first two hits one shadow ray and one continuation ray).

Each round also runs pathbench-bench's raw Embree ray casts on the same scene, and each
strategy's rays/s is set against Embree's raw rate for the render's own ray mix
(tools/raw_embree_mix.py; watertight strategies only: the benchmarks use the tracer's
robust Embree scene).

Writes results/<machine>/mitsuba-vs-pathbench.json (strict JSON, with the machine
fingerprint of tools/machine.py) and .md, <machine> being the slug pb::machine_slug gives,
with the CPU's vector flags (which ISAs this host has) and the ISA each pathbench run used,
and records the run in the project history (`pathbench history record` of the .bench.json
beside them; series `mitsuba/cpu/...`, tools/mitsuba_speed_history.py; --no-history skips it).
Files: the runners (mitsuba_speed_runners.py), the report (mitsuba_speed_report.py), the
history rows (mitsuba_speed_history.py); this file runs the rounds.

`--emulate-isa avx2` stands in for an AVX2-only host on an AVX-512 one (tools/isa_emulation.py):
every pathbench run gets `--isa avx2`, Embree (pathbench's, pathbench-bench's and the one
Mitsuba bundles) is capped by the LD_PRELOAD shim scripts/isa_cap/embree_isa_cap.c, Dr.Jit's
LLVM backend is set to haswell with 8 lanes, and glibc's dispatch is capped by its tunables.
The tool builds the shim (build/isa_cap/, or --embree-shim) and re-executes itself with it
preloaded. Each cap is read back and recorded (the results' `emulation`); a cap that did not
take stops the run. Results go to mitsuba-vs-pathbench-avx2cap.json and .md, never over the
native ones. It is an emulation: the caches, clocks and cores are the AVX-512 host's.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import isa_emulation  # noqa: E402
import mitsuba_speed_history as history  # noqa: E402
import raw_embree_mix  # noqa: E402
from machine import cpu_model, cpu_vector_flags, host_fingerprint, machine_slug  # noqa: E402
from mitsuba_speed_report import add_speedups, layout_lines, markdown, spread, write_json  # noqa: E402,F401
from mitsuba_speed_runners import (FULL_TRACE_RAYS_PER_SAMPLE, MitsubaRunner, PathbenchRunner,  # noqa: E402,F401
                                   load_sample, loadavg)

ROOT = Path(__file__).resolve().parent.parent
# The fewest renders whose median the issue trusts (issue 35): below, the results say so.
MIN_ROUNDS, MIN_MITSUBA_RENDERS = 5, 10


def results_stem(emulate_isa=None):
    """The results' file name without suffix: an emulated host's never overwrite the native ones."""
    return "mitsuba-vs-pathbench" + (f"-{emulate_isa}cap" if emulate_isa else "")


def emulated_specs(specs, isa):
    """Every pathbench spec with `isa=<isa>` (the emulated host has no other), refusing another ISA."""
    out = []
    for s in specs:
        asked = [f.split("=", 1)[1] for f in s.split("/")[1:] if f.startswith("isa=")]
        if any(x != isa for x in asked):
            print(f"mitsuba_speed.py: error: --emulate-isa {isa}: spec {s!r} asks for another ISA", file=sys.stderr)
            raise SystemExit(2)  # a bad combination of options, as argparse's own errors
        out.append(s if asked else f"{s}/isa={isa}")
    return list(dict.fromkeys(out))


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pathbench", default=str(ROOT / "build" / "bin" / "pathbench"))
    ap.add_argument("--spp", type=int, default=800)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--rounds", type=int, default=MIN_ROUNDS,
                    help=f"interleaved rounds (default {MIN_ROUNDS}): each pathbench run once per round")
    ap.add_argument("--mitsuba-per-round", type=int, default=MIN_MITSUBA_RENDERS // MIN_ROUNDS,
                    help="Mitsuba renders per round, half before and half after the pathbench runs (default 2)")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--strategies", default="pixel,wavefront,pixel/no-watertight,wavefront/no-watertight",
                    help="strategies, each optionally with flags after '/' (default: both, watertight or not)")
    ap.add_argument("--out-dir", help="default: results/<machine>")
    ap.add_argument("--isa", default="",
                    help="comma list of `pathbench render --isa` values (auto, avx512, avx2, scalar): each strategy "
                         "once per ISA (default: the binary's own choice, auto)")
    ap.add_argument("--no-raw", action="store_true", help="skip the raw Embree ray casts (pathbench-bench)")
    ap.add_argument("--no-history", action="store_true", help="do not record the run in the project history")
    ap.add_argument("--history-db", help="history database (default: the project's results/history/history.sqlite)")
    ap.add_argument("--baseline", help="another pathbench binary (e.g. a build of an older commit): its pixel and "
                                       "wavefront strategies run in the same interleaved rounds, labelled "
                                       "'STRATEGY@baseline', so a before/after ratio comes from one run")
    ap.add_argument("--emulate-isa", choices=sorted(isa_emulation.TARGETS),
                    help="on an AVX-512 host, cap every component of both renderers at this ISA (pathbench --isa, "
                         "Embree through the LD_PRELOAD shim, Dr.Jit's LLVM target, glibc's dispatch) to stand in "
                         "for a host that has only it; results go to mitsuba-vs-pathbench-<isa>cap.*")
    ap.add_argument("--embree-shim", default=str(isa_emulation.SHIM_DEFAULT),
                    help="the shim for --emulate-isa (built there from scripts/isa_cap/ when missing or older)")
    a = ap.parse_args(argv)
    for name in ("spp", "size", "rounds", "mitsuba_per_round"):
        if getattr(a, name) < 1:
            ap.error(f"--{name.replace('_', '-')} {getattr(a, name)}: must be at least 1")
    return a


def pathbench_runners(a, specs, tmp, emulate):
    ours = {s: PathbenchRunner(a.pathbench, s, a.spp, a.size, tmp, emulate_isa=emulate) for s in specs}
    if a.baseline:
        for s in emulated_specs(["pixel", "wavefront"], emulate) if emulate else ("pixel", "wavefront"):
            label = f"{s.split('/')[0]}@baseline"
            ours[label] = PathbenchRunner(a.baseline, s, a.spp, a.size, tmp, label=label, emulate_isa=emulate)
    return ours


def run_rounds(a, mitsuba, ours, bench, emulate):
    """Interleaved rounds: half of the round's Mitsuba renders, every pathbench run, the other
    half; so a change of load during the run falls on every renderer alike. The raw Embree
    rates of each round (pathbench-bench), where it is built."""
    raw_rounds, bench_context = [], {}
    before = a.mitsuba_per_round // 2 + a.mitsuba_per_round % 2
    for k in range(a.rounds):
        for _ in range(before):
            mitsuba.run(k)
        for r in ours.values():
            r.run(k)
        for _ in range(a.mitsuba_per_round - before):
            mitsuba.run(k)
        if bench.is_file() and not a.no_raw:
            raw_rounds.append(raw_embree_mix.measure(bench, context=bench_context))
            if emulate:
                isa_emulation.check_embree((bench_context.get("fingerprint") or {}).get("embree"),
                                           "pathbench-bench", emulate)
            print("raw Embree: " + ", ".join(f"{n.split('/')[2]}/{n.split('/')[3]} {v / 1e6:.1f} M/s"
                                             for n, v in sorted(raw_rounds[-1].items())), flush=True)
    return raw_rounds, bench_context


def raw_embree_result(raw_rounds, pb, ours):
    rates = raw_embree_mix.median_rates(raw_rounds)
    out = {"rates": rates, "rounds": len(raw_rounds), "mix": {}}
    for s, r in pb.items():
        if ours[s].watertight and ours[s].strategy in raw_embree_mix.WIDTH:  # the benchmarks are robust mode
            strategy = ours[s].strategy
            raw = raw_embree_mix.mix_rate(r["rays"], rates, strategy)
            out["mix"][s] = {
                "calls": "rtcIntersect1 / rtcOccluded1" if strategy == "pixel" else "16-wide packets",
                "isa": r.get("isa"),
                "raw_rays_per_second": round(raw), "share": round(r["median_rays_per_second"] / raw, 4)}
    return out


def too_short(res):
    """The renderers whose timings hold a zero (a frame too small to time), by name."""
    named = {"mitsuba": res["mitsuba"]} | {f"pathbench {s}": r for s, r in res["pathbench"].items()}
    return [name for name, r in named.items() if min(r["seconds"]) <= 0]


def add_rates(res, a):
    samples = a.size * a.size * a.spp
    m = res["mitsuba"]
    m["samples_per_second"] = round(samples / m["median_seconds"])
    m["rays_per_sample_assumed"] = FULL_TRACE_RAYS_PER_SAMPLE
    m["estimated_rays_per_second"] = round(samples / m["median_seconds"] * FULL_TRACE_RAYS_PER_SAMPLE)
    m["rays_counted"] = False
    for r in res["pathbench"].values():
        r["samples_per_second"] = round(samples / r["median_seconds"])
    add_speedups(res)


def main(argv=None):
    a = parse_args(argv)
    specs = a.strategies.split(",")
    if a.isa:
        specs = [f"{s}/isa={i}" for s in specs for i in a.isa.split(",")]
    if not Path(a.pathbench).is_file():
        print(f"mitsuba_speed.py: error: {a.pathbench}: not built (run scripts/build.sh, or pass --pathbench)",
              file=sys.stderr)
        return 2
    emulate = a.emulate_isa
    if emulate:
        specs = emulated_specs(specs, emulate)
        if not isa_emulation.host_has_avx512(cpu_vector_flags()):
            sys.exit(f"--emulate-isa {emulate}: this host has no AVX-512, so it is a real host of its own ISA: "
                     "run without --emulate-isa")
        shim = isa_emulation.build_shim(Path(a.embree_shim))
        isa_emulation.ensure_preloaded(emulate, shim, argv)  # re-executes the tool with the shim preloaded

    now = datetime.now(timezone.utc)
    n_mitsuba = a.rounds * a.mitsuba_per_round
    res = {
        "date": now.strftime("%Y-%m-%d %H:%M UTC"),
        "machine": {"slug": machine_slug(), "cpu": cpu_model(), "hardware_threads": os.cpu_count(),
                    "cpu_flags": cpu_vector_flags()},
        "fingerprint": host_fingerprint(),
        "settings": {"scene": "paper-cornell", "width": a.size, "height": a.size, "spp": a.spp, "bounces": 2,
                     "sampling": "nee", "filter": "box", "rounds": a.rounds, "mitsuba_per_round": a.mitsuba_per_round,
                     "mitsuba_renders": n_mitsuba,
                     "enough_repetitions": a.rounds >= MIN_ROUNDS and n_mitsuba >= MIN_MITSUBA_RENDERS},
        "load_average_before": loadavg(),
        "load_before": load_sample(),
    }
    if not res["settings"]["enough_repetitions"]:
        print(f"mitsuba_speed.py: note: {a.rounds} rounds, {n_mitsuba} Mitsuba renders: fewer than the "
              f"{MIN_ROUNDS} rounds and {MIN_MITSUBA_RENDERS} renders a trusted ratio takes", file=sys.stderr)
    bench = Path(a.pathbench).parent / "pathbench-bench"
    with tempfile.TemporaryDirectory() as tmp:
        mitsuba = MitsubaRunner(a.spp, a.variant, a.size, emulate_isa=emulate)
        ours = pathbench_runners(a, specs, tmp, emulate)
        raw_rounds, bench_context = run_rounds(a, mitsuba, ours, bench, emulate)
        res["mitsuba"] = mitsuba.result()
        res["pathbench"] = {s: r.result() for s, r in ours.items()}
    if raw_rounds:
        res["raw_embree"] = raw_embree_result(raw_rounds, res["pathbench"], ours)
    res["load_average_after"] = loadavg()
    res["load_after"] = load_sample()
    if emulate:
        pb = res["pathbench"]
        first = next(iter(ours.values())).runs[0]["report"]
        res["emulation"] = isa_emulation.record(
            emulate, shim, mitsuba.emulation["drjit"], mitsuba.emulation["embree"],
            {s: r["embree"] for s, r in pb.items()}, (bench_context.get("fingerprint") or {}).get("embree"),
            {s: r["isa"] for s, r in pb.items()}, (first.get("fingerprint") or {}).get("build"))
    if too_short(res):
        print(f"mitsuba_speed.py: error: {', '.join(too_short(res))}: a render took 0 s (the frame is too small to "
              "time); raise --size or --spp", file=sys.stderr)
        return 2
    add_rates(res, a)

    out = Path(a.out_dir) if a.out_dir else ROOT / "results" / res["machine"]["slug"]
    out.mkdir(parents=True, exist_ok=True)
    stem = results_stem(emulate)
    write_json(out / f"{stem}.json", res)
    md = markdown(res)
    (out / f"{stem}.md").write_text(md)
    print(md)
    bench_json = out / f"{stem}.bench.json"
    write_json(bench_json, history.bench_json(res, now.isoformat(timespec="seconds")))
    if a.no_history:
        return 0
    status = history.record(bench_json, a.history_db)
    if status != 0:
        print(f"mitsuba_speed.py: error: the run was measured ({out / stem}.json) but not recorded in the history "
              f"(exit {status}); record it later: pathbench history record {bench_json}", file=sys.stderr)
    return status


if __name__ == "__main__":
    sys.exit(main())
