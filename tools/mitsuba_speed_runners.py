"""The two renderers of tools/mitsuba_speed.py, each timed one render at a time: Mitsuba 3 on
paper-cornell (MitsubaRunner) and `pathbench render` with one strategy (PathbenchRunner).
Every timed render is kept with its round and the machine's load just before and just after it
(`load_sample`), so a reader of the JSON sees which renders shared the machine with something else."""
from __future__ import annotations

import json
import os
import resource
import subprocess
import time
from pathlib import Path

import isa_emulation
import mitsuba_scene as ms
from mitsuba_speed_report import spread

# Rays per sample of this estimator when every segment is a closest-hit or shadow query
# (camera ray; at each of the first two hits a shadow ray and a continuation ray), as
# pathbench measured it at commit 3d3ac70, before it answered the last continuation ray
# with an emitter test. Mitsuba traces every segment, and does not count its rays.
FULL_TRACE_RAYS_PER_SAMPLE = 4.504


def loadavg():
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def load_sample():
    """The machine's load now: load averages (1, 5, 15 min) and the CPUs this process may use."""
    try:
        usable = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        usable = os.cpu_count()
    return {"loadavg": loadavg(), "cpu_count": os.cpu_count(), "usable_cpus": usable}


def timed(fn, round_index):
    """fn() timed, as a run record: seconds, its round, the load before and after. fn may
    return a dict of more fields for the record."""
    before = load_sample()
    t0 = time.perf_counter()
    extra = fn() or {}
    seconds = time.perf_counter() - t0
    return {"round": round_index, "seconds": seconds, "load_before": before, "load_after": load_sample()} | extra


def _runs_json(runs):
    return [{"round": r["round"], "seconds": round(r["seconds"], 3), "load_before": r["load_before"],
             "load_after": r["load_after"]} for r in runs]


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
        self.runs = []
        print(f"mitsuba {variant}: warm-up {self.warmup:.2f} s (excluded)", flush=True)

    def _render(self):
        self.dr.sync_thread()
        # ms.render copies the image to numpy, so the render is complete when it returns.
        self.img = ms.render(self.mi, self.scene, self.spp, seed=len(self.runs) + 1)
        self.dr.sync_thread()

    def run(self, round_index=0):
        self.runs.append(timed(self._render, round_index))
        print(f"mitsuba {self.variant}: render {len(self.runs)}: {self.runs[-1]['seconds']:.2f} s", flush=True)

    def result(self):
        secs = [r["seconds"] for r in self.runs]
        return {
            "renderer": f"Mitsuba {self.mi.__version__}",
            "variant": self.variant,
            "integrator": f"path, max_depth {ms.MAX_DEPTH}, rr_depth beyond max_depth (no Russian roulette)",
            "threads": "all (Dr.Jit's thread pool)",
            "llvm_target": self.llvm_target,  # Dr.Jit's cpu, features and vector width, read back
            "warmup_seconds": round(self.warmup, 3),
            "seconds": [round(t, 3) for t in secs],
            "median_seconds": spread(secs)["median"],
            "spread": spread(secs),
            "runs": _runs_json(self.runs),
            "image_mean_rgb": [round(float(x), 5) for x in self.img.reshape(-1, 3).mean(axis=0)],
            "peak_rss_bytes_this_process": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
        }


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

    def command(self, seed, image, report):
        return [str(self.binary), "render", "--scene", "paper-cornell", "--width", str(self.size), "--height",
                str(self.size), "--spp", str(self.spp), "--bounces", "2", "--sampling", "nee", "--strategy",
                self.strategy, *self.flags, "--seed", str(seed), "--out", str(image), "--report", str(report),
                "--quiet"]

    def _render(self):
        k = len(self.runs)
        name = self.label.replace("/", "-")
        report, image = self.tmp / f"{name}-{k}.json", self.tmp / f"{name}-{k}.pfm"
        subprocess.run(self.command(k + 1, image, report), check=True)
        r = json.loads(report.read_text())
        r["image_mean_rgb"] = [round(float(x), 5) for x in ms.read_pfm(image).reshape(-1, 3).mean(axis=0)]
        if self.emulate_isa:
            isa_emulation.check_pathbench_report(r, f"pathbench {self.label}", self.emulate_isa)
        return {"report": r}

    def run(self, round_index=0):
        rec = timed(self._render, round_index)
        rec["wall_seconds"], rec["seconds"] = rec["seconds"], rec["report"]["seconds"]  # its own render time
        self.runs.append(rec)
        r = rec["report"]
        print(f"pathbench {self.label}: render {len(self.runs)}: {r['seconds']:.2f} s, "
              f"{r['rays_per_second'] / 1e6:.2f} M rays/s", flush=True)

    def result(self):
        reports = [r["report"] for r in self.runs]
        secs = [r["seconds"] for r in reports]
        s = spread(secs)
        med = min(reports, key=lambda r: abs(r["seconds"] - s["median"]))  # the median run
        return {
            "command": f"pathbench render --scene paper-cornell --width {self.size} --height {self.size} "
                       f"--spp {self.spp} --bounces 2 --sampling nee --strategy {self.strategy} {' '.join(self.flags)}".rstrip(),
            "seconds": [round(x, 3) for x in secs],
            "median_seconds": s["median"],
            "spread": s,
            "runs": _runs_json(self.runs),
            "rays_per_sample": reports[0]["rays"]["total"] / reports[0]["paths"],
            "rays": reports[0]["rays"],
            "median_rays_per_second": round(spread([r["rays_per_second"] for r in reports])["median"]),
            "threads": med["machine"]["threads"],
            "git_revision": med.get("git_revision"),
            "compiler": med.get("compiler"),
            "peak_host_bytes": med.get("peak_host_bytes"),
            "image_mean_rgb": med["image_mean_rgb"],
            "film_hash": med.get("film_hash"),
            "embree_layout": med.get("embree_layout"),  # the report's: asked, used, why, probe times
            "isa": med.get("isa"),  # the path step's instruction set, as the report names it
            "isa_asked": med.get("isa_asked"),
            "embree": (med.get("fingerprint") or {}).get("embree"),  # its Embree device: version, native widths
        }
