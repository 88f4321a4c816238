#!/usr/bin/env python3
"""Speed of pathbench's CPU tracer against Mitsuba 3 on the paper's scene, on this
machine, back to back in one run (interleaved rounds). Re-run after any change to the CPU tracer:

    .venv/bin/python tools/mitsuba_speed.py          # needs build/bin/pathbench (scripts/build.sh)

Both render paper-cornell at 256 x 256, 800 spp, two bounces (Mitsuba: `path`,
max_depth = 3; pathbench: --bounces 2 --sampling nee), box filter, all hardware
threads. Mitsuba 3 runs its llvm_ad_rgb variant (needs libLLVM: apt-get install
libllvm19); one warm-up render (JIT compilation) is excluded, then --repeats renders
are timed and the median is reported. pathbench runs `pathbench render ... --strategy
pixel|wavefront --report` --repeats times each, median of its own reported seconds;
with `--isa avx512,avx2,...` each strategy once per instruction set of the batched path
step (`pathbench render --isa`), so one run compares them on this host.
The runs go in rounds (Mitsuba, pixel, wavefront; again), so load that comes and goes
during the run is shared out evenly.

Mitsuba does not count rays. Its rays per second are an ESTIMATE: its samples per
second times pathbench's measured rays per sample for the same estimator (camera ray,
then at each of the first two hits one shadow ray and one continuation ray).

Each round also runs pathbench-bench's raw Embree ray casts on the same scene, and each
strategy's rays/s is set against Embree's raw rate for the render's own ray mix
(tools/raw_embree_mix.py; watertight strategies only: the benchmarks use the tracer's
robust Embree scene).

Writes results/<machine>/mitsuba-vs-pathbench.json and .md, <machine> being the slug
pb::machine_slug gives (tools/machine.py), with the CPU's vector flags (which ISAs this
host has) and the ISA each pathbench run used.

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
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mitsuba_scene as ms  # noqa: E402
import isa_emulation  # noqa: E402
import raw_embree_mix  # noqa: E402
from machine import cpu_model, cpu_vector_flags, host_fingerprint, machine_slug  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def loadavg():
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


class MitsubaRunner:
    """Mitsuba 3 on paper-cornell; the constructor loads the scene and does the
    warm-up render (JIT compilation), excluded from the timings."""

    def __init__(self, spp, variant, size, emulate_isa=None):
        self.mi = ms.import_mitsuba(variant)
        import drjit as dr  # noqa: PLC0415

        self.dr, self.spp, self.variant = dr, spp, variant
        self.emulation = None  # Dr.Jit's capped target, read back, and Mitsuba's Embree device
        if emulate_isa:  # after set_variant (LLVM initialised), before any kernel of the scene
            native_probe = isa_emulation.drjit_codegen_probe(dr)
            self.emulation = {"drjit": isa_emulation.drjit_set_target(dr, emulate_isa)}
            self.emulation["drjit"]["native_probe"] = native_probe
            self.emulation["drjit"]["probe"] = isa_emulation.drjit_codegen_probe(dr)
            isa_emulation.check_drjit(self.emulation["drjit"], emulate_isa)
            print(f"Dr.Jit LLVM target: {self.emulation['drjit']['read_back']}, probe "
                  f"{self.emulation['drjit']['probe']}", flush=True)
        try:
            self.llvm_target = isa_emulation.drjit_target(dr) if variant.startswith("llvm") else None
        except (OSError, AttributeError):  # another Dr.Jit: jit.h's functions not found
            self.llvm_target = None
        self.scene = ms.load_scene(self.mi, width=size, height=size, spp=spp)
        if emulate_isa:  # Mitsuba made its Embree device while loading the scene
            self.emulation["embree"] = isa_emulation.shim_report()
            isa_emulation.check_embree(self.emulation["embree"], "Mitsuba", emulate_isa)
            print(f"Mitsuba's Embree through the shim: {self.emulation['embree']}", flush=True)
        t0 = time.perf_counter()
        self.img = ms.render(self.mi, self.scene, spp, seed=0)
        self.warmup = time.perf_counter() - t0
        self.times = []
        print(f"mitsuba {variant}: warm-up {self.warmup:.2f} s (excluded)", flush=True)

    def run(self):
        self.dr.sync_thread()
        t0 = time.perf_counter()
        # ms.render copies the image to numpy, so the render is complete when it returns.
        self.img = ms.render(self.mi, self.scene, self.spp, seed=len(self.times) + 1)
        self.dr.sync_thread()
        self.times.append(time.perf_counter() - t0)
        print(f"mitsuba {self.variant}: render {len(self.times)}: {self.times[-1]:.2f} s", flush=True)

    def result(self):
        return {
            "renderer": f"Mitsuba {self.mi.__version__}",
            "variant": self.variant,
            "integrator": f"path, max_depth {ms.MAX_DEPTH}, rr_depth beyond max_depth (no Russian roulette)",
            "threads": "all (Dr.Jit's thread pool)",
            "llvm_target": self.llvm_target,  # Dr.Jit's cpu, features and vector width, read back
            "warmup_seconds": round(self.warmup, 3),
            "seconds": [round(t, 3) for t in self.times],
            "median_seconds": round(statistics.median(self.times), 3),
            "image_mean_rgb": [round(float(x), 5) for x in self.img.reshape(-1, 3).mean(axis=0)],
            "peak_rss_bytes_this_process": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
        }


# Rays per sample of this estimator when every segment is a closest-hit or shadow query
# (camera ray; at each of the first two hits a shadow ray and a continuation ray), as
# pathbench measured it at commit 3d3ac70, before it answered the last continuation ray
# with an emitter test. Mitsuba traces every segment, and does not count its rays.
FULL_TRACE_RAYS_PER_SAMPLE = 4.504


class PathbenchRunner:
    """`pathbench render` on paper-cornell with one strategy; its own report's seconds.
    `spec` is a strategy, optionally with flags after '/': "wavefront/no-watertight",
    "pixel/isa=avx2" (an option with its value)."""

    def __init__(self, binary, spec, spp, size, tmp, label=None, emulate_isa=None):
        self.strategy, *flags = spec.split("/")
        self.flags = [x for f in flags for x in (f"--{f}".split("=", 1))]
        self.watertight = "no-watertight" not in flags
        self.label = label or spec
        self.binary, self.spp, self.size, self.tmp = binary, spp, size, Path(tmp)
        self.emulate_isa = emulate_isa
        self.runs = []

    def run(self):
        k = len(self.runs)
        name = self.label.replace("/", "-")
        report = self.tmp / f"{name}-{k}.json"
        image = self.tmp / f"{name}-{k}.pfm"
        cmd = [str(self.binary), "render", "--scene", "paper-cornell", "--width", str(self.size), "--height",
               str(self.size), "--spp", str(self.spp), "--bounces", "2", "--sampling", "nee", "--strategy",
               self.strategy, *self.flags, "--seed", str(k + 1), "--out", str(image), "--report", str(report), "--quiet"]
        subprocess.run(cmd, check=True)
        r = json.loads(report.read_text())
        r["image_mean_rgb"] = [round(float(x), 5) for x in ms.read_pfm(image).reshape(-1, 3).mean(axis=0)]
        if self.emulate_isa:
            isa_emulation.check_pathbench_report(r, f"pathbench {self.label}", self.emulate_isa)
        self.runs.append(r)
        print(f"pathbench {self.label}: render {k + 1}: {r['seconds']:.2f} s, "
              f"{r['rays_per_second'] / 1e6:.2f} M rays/s", flush=True)

    def result(self):
        runs = self.runs
        secs = [r["seconds"] for r in runs]
        med = min(runs, key=lambda r: abs(r["seconds"] - statistics.median(secs)))  # the median run
        return {
            "command": f"pathbench render --scene paper-cornell --width {self.size} --height {self.size} "
                       f"--spp {self.spp} --bounces 2 --sampling nee --strategy {self.strategy} {' '.join(self.flags)}".rstrip(),
            "seconds": [round(s, 3) for s in secs],
            "median_seconds": round(statistics.median(secs), 3),
            "rays_per_sample": runs[0]["rays"]["total"] / runs[0]["paths"],
            "rays": runs[0]["rays"],
            "median_rays_per_second": round(statistics.median(r["rays_per_second"] for r in runs)),
            "threads": med["machine"]["threads"],
            "git_revision": med.get("git_revision"),
            "compiler": med.get("compiler"),
            "peak_host_bytes": med.get("peak_host_bytes"),
            "image_mean_rgb": med["image_mean_rgb"],
            "embree_layout": med.get("embree_layout"),  # the report's: asked, used, why, probe times
            "isa": med.get("isa"),  # the path step's instruction set, as the report names it
            "isa_asked": med.get("isa_asked"),
            "embree": (med.get("fingerprint") or {}).get("embree"),  # its Embree device: version, native widths
        }


def layout_lines(pb):
    """Which Embree layout each pathbench run traced (`--embree-layout auto` decides per
    process, from a probe it times), so the table says what was measured."""
    parts = []
    for strategy, r in pb.items():
        lay = r.get("embree_layout")
        if not lay:
            continue
        probe = lay.get("probe_ns_per_ray")
        timed = (f", probe {probe['triangles']:.0f} ns/ray as triangles, {probe['quads']:.0f} as quads"
                 if probe else "")
        parts.append(f"{strategy}: {lay['used']} ({lay['why']}{timed})")
    if not parts:
        return []
    return ["pathbench's Embree layout (`--embree-layout " + next(iter(pb.values()))["embree_layout"]["asked"]
            + "`; the raw rates above come from the same choice): " + "; ".join(parts) + "."]


def markdown(res):
    m, pb = res["mitsuba"], res["pathbench"]
    spp, px = res["settings"]["spp"], res["settings"]["width"] * res["settings"]["height"]
    em = res.get("emulation")
    lines = [
        f"# Mitsuba 3 vs pathbench on {res['machine']['cpu']}"
        + (f", emulating an {em['isa'].upper()}-only host" if em else ""),
        "",
        f"paper-cornell, {res['settings']['width']}x{res['settings']['height']}, {spp} spp, two bounces "
        "(Mitsuba `path` max_depth 3; pathbench `--bounces 2 --sampling nee`), box filter, "
        f"{res['machine']['hardware_threads']} hardware threads, measured {res['date']} "
        f"(load average before {res['load_average_before']}, after {res['load_average_after']}).",
    ]
    if em:
        lines += isa_emulation.markdown_lines(em)
    flags = res["machine"].get("cpu_flags")
    if flags is not None:
        lines += ["", "CPU vector flags: " + (" ".join(flags) or "none beyond SSE2") + "; pathbench's path step ran "
                  + ", ".join(f"{s}: {r.get('isa') or '?'}" for s, r in pb.items()) + "."]
    # Only the load before the run says whether something else was running: during it,
    # the renderers' own threads raise the load average to about the thread count.
    load = res["load_average_before"][0] if res["load_average_before"] else 0
    if load > 0.5 * res["machine"]["hardware_threads"]:
        lines += ["",
                  f"**The machine was busy** (1-minute load average {load} before the run, on "
                  f"{res['machine']['hardware_threads']} hardware threads): every render was slowed. The renderers ran "
                  "in interleaved rounds, so the ratio is the informative number; absolute times are not."]
    lines += [
        "",
        "| renderer | median s (runs) | samples/s | rays/s | speed-up over Mitsuba |",
        "|---|---|---|---|---|",
    ]
    ms_med = m["median_seconds"]
    lines.append(f"| {m['renderer']} {m['variant']} | {ms_med:.2f} ({', '.join(f'{s:.2f}' for s in m['seconds'])}) "
                 f"| {px * spp / ms_med / 1e6:.2f} M | ~{m['estimated_rays_per_second'] / 1e6:.1f} M (estimate) | 1.00x |")
    for strategy, r in pb.items():
        lines.append(f"| pathbench cpu/{strategy} | {r['median_seconds']:.2f} "
                     f"({', '.join(f'{s:.2f}' for s in r['seconds'])}) | {px * spp / r['median_seconds'] / 1e6:.2f} M "
                     f"| {r['median_rays_per_second'] / 1e6:.1f} M | {ms_med / r['median_seconds']:.2f}x |")
    raw = res.get("raw_embree")
    if raw:
        lines += ["", "Against Embree's raw ray-cast rate for each render's own ray mix (camera rays as coherent "
                  "closest hits, bounce rays as incoherent closest hits, shadow rays as incoherent occlusion rays; "
                  "pathbench-bench raycast benchmarks on this scene, run once per round, medians; aim: 80%):", "",
                  "| run | rays by kind (camera / bounce / shadow) | Embree calls | raw rate, same mix | "
                  "pathbench rays/s | share of raw |", "|---|---|---|---:|---:|---:|"]
        for strategy, m_ in raw["mix"].items():
            r = pb[strategy]
            lines.append(f"| {strategy} | {r['rays']['camera'] / 1e6:.1f} M / {r['rays']['bounce'] / 1e6:.1f} M / "
                         f"{r['rays']['shadow'] / 1e6:.1f} M | {m_['calls']} | {m_['raw_rays_per_second'] / 1e6:.1f} M "
                         f"| {r['median_rays_per_second'] / 1e6:.1f} M | {100 * m_['share']:.0f}% |")
        lines += ["", "Raw rates (M rays/s): " + ", ".join(
            f"{n.replace('raycast/cpu/', '').replace('/paper-cornell/real_time', '')} {v / 1e6:.1f}"
            for n, v in sorted(raw["rates"].items())) + "."]
    lines += [
        "",
        f"Mitsuba's warm-up render (JIT compilation, excluded): {m['warmup_seconds']:.2f} s.",
        f"Mitsuba rays/s is an estimate: its samples/s x {m['rays_per_sample_assumed']:.3f} rays per sample, what "
        "pathbench measured for this estimator when it traced every segment (Mitsuba does not count rays). pathbench "
        "now answers the last continuation ray with an emitter test and traces fewer rays per sample (rays/s counts "
        "only rays traced). `no-watertight`: Embree without its robust mode (faster; rays can slip through edges).",
        f"Image means (R, G, B): Mitsuba {m['image_mean_rgb']}, pathbench "
        f"{next(iter(pb.values()))['image_mean_rgb']}.",
        *layout_lines(pb),
        f"pathbench revision {next(iter(pb.values()))['git_revision']}, {next(iter(pb.values()))['compiler']}.",
        "",
        "Re-run: `.venv/bin/python tools/mitsuba_speed.py"
        + (f" --emulate-isa {em['isa']}" if em else "") + "` (after `scripts/build.sh`).",
        "",
    ]
    return "\n".join(lines)


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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pathbench", default=str(ROOT / "build" / "bin" / "pathbench"))
    ap.add_argument("--spp", type=int, default=800)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--strategies", default="pixel,wavefront,pixel/no-watertight,wavefront/no-watertight",
                    help="strategies, each optionally with flags after '/' (default: both, watertight or not)")
    ap.add_argument("--out-dir", help="default: results/<machine>")
    ap.add_argument("--isa", default="",
                    help="comma list of `pathbench render --isa` values (auto, avx512, avx2, scalar): each strategy "
                         "once per ISA (default: the binary's own choice, auto)")
    ap.add_argument("--no-raw", action="store_true", help="skip the raw Embree ray casts (pathbench-bench)")
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
    specs = [s for s in a.strategies.split(",")]
    if a.isa:
        specs = [f"{s}/isa={i}" for s in specs for i in a.isa.split(",")]
    if not Path(a.pathbench).is_file():
        sys.exit(f"{a.pathbench}: not built (run scripts/build.sh, or pass --pathbench)")
    emulate = a.emulate_isa
    if emulate:
        specs = emulated_specs(specs, emulate)
        if not isa_emulation.host_has_avx512(cpu_vector_flags()):
            sys.exit(f"--emulate-isa {emulate}: this host has no AVX-512, so it is a real host of its own ISA: "
                     "run without --emulate-isa")
        shim = isa_emulation.build_shim(Path(a.embree_shim))
        isa_emulation.ensure_preloaded(emulate, shim, argv)  # re-executes the tool with the shim preloaded

    res = {
        "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": {"slug": machine_slug(), "cpu": cpu_model(), "hardware_threads": os.cpu_count(),
                    "cpu_flags": cpu_vector_flags()},
        "fingerprint": host_fingerprint(),
        "settings": {"scene": "paper-cornell", "width": a.size, "height": a.size, "spp": a.spp, "bounces": 2,
                     "sampling": "nee", "filter": "box", "repeats": a.repeats},
        "load_average_before": loadavg(),
    }
    # Interleaved rounds (Mitsuba, then each pathbench strategy, repeated), so a change
    # of load during the run falls on every renderer alike.
    bench = Path(a.pathbench).parent / "pathbench-bench"
    raw_rounds = []
    with tempfile.TemporaryDirectory() as tmp:
        mitsuba = MitsubaRunner(a.spp, a.variant, a.size, emulate_isa=emulate)
        ours = {s: PathbenchRunner(a.pathbench, s, a.spp, a.size, tmp, emulate_isa=emulate) for s in specs}
        if a.baseline:
            for s in emulated_specs(["pixel", "wavefront"], emulate) if emulate else ("pixel", "wavefront"):
                label = f"{s.split('/')[0]}@baseline"
                ours[label] = PathbenchRunner(a.baseline, s, a.spp, a.size, tmp, label=label, emulate_isa=emulate)
        bench_context = {}
        for _ in range(a.repeats):
            mitsuba.run()
            for r in ours.values():
                r.run()
            if bench.is_file() and not a.no_raw:
                raw_rounds.append(raw_embree_mix.measure(bench, context=bench_context))
                if emulate:
                    isa_emulation.check_embree((bench_context.get("fingerprint") or {}).get("embree"),
                                               "pathbench-bench", emulate)
                print("raw Embree: " + ", ".join(f"{n.split('/')[2]}/{n.split('/')[3]} {v / 1e6:.1f} M/s"
                                                 for n, v in sorted(raw_rounds[-1].items())), flush=True)
        res["mitsuba"] = mitsuba.result()
        res["pathbench"] = {s: r.result() for s, r in ours.items()}
    if raw_rounds:
        rates = raw_embree_mix.median_rates(raw_rounds)
        res["raw_embree"] = {"rates": rates, "rounds": len(raw_rounds), "mix": {}}
        for s, r in res["pathbench"].items():
            if ours[s].watertight and ours[s].strategy in raw_embree_mix.WIDTH:  # the benchmarks are robust mode
                strategy = ours[s].strategy
                raw = raw_embree_mix.mix_rate(r["rays"], rates, strategy)
                res["raw_embree"]["mix"][s] = {
                    "calls": "rtcIntersect1 / rtcOccluded1" if strategy == "pixel" else "16-wide packets",
                    "isa": r.get("isa"),
                    "raw_rays_per_second": round(raw), "share": round(r["median_rays_per_second"] / raw, 4)}
    res["load_average_after"] = loadavg()
    if emulate:
        pb = res["pathbench"]
        first = next(iter(ours.values())).runs[0]
        res["emulation"] = isa_emulation.record(
            emulate, shim, mitsuba.emulation["drjit"], mitsuba.emulation["embree"],
            {s: r["embree"] for s, r in pb.items()}, (bench_context.get("fingerprint") or {}).get("embree"),
            {s: r["isa"] for s, r in pb.items()}, (first.get("fingerprint") or {}).get("build"))

    samples = a.size * a.size * a.spp
    rps = FULL_TRACE_RAYS_PER_SAMPLE
    m = res["mitsuba"]
    m["samples_per_second"] = round(samples / m["median_seconds"])
    m["rays_per_sample_assumed"] = rps
    m["estimated_rays_per_second"] = round(samples / m["median_seconds"] * rps)
    m["rays_counted"] = False
    for r in res["pathbench"].values():
        r["samples_per_second"] = round(samples / r["median_seconds"])
        r["speedup_vs_mitsuba"] = round(m["median_seconds"] / r["median_seconds"], 3)

    out = Path(a.out_dir) if a.out_dir else ROOT / "results" / res["machine"]["slug"]
    out.mkdir(parents=True, exist_ok=True)
    stem = results_stem(emulate)
    (out / f"{stem}.json").write_text(json.dumps(res, indent=2) + "\n")
    md = markdown(res)
    (out / f"{stem}.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
