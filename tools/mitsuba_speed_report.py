"""The report of tools/mitsuba_speed.py: the spread of a set of timings (median, min-max,
quartiles), the speed-up over Mitsuba round by round, the Markdown table and the strict JSON file."""
from __future__ import annotations

import json
import statistics
from pathlib import Path

import isa_emulation
from atomic_file import write_text_atomically


def spread(values):
    """Median, min, max, quartiles (inclusive method: the data's own range) and IQR, rounded to ms."""
    v = sorted(float(x) for x in values)
    if not v:
        raise ValueError("no timings")
    q1, _, q3 = statistics.quantiles(v, n=4, method="inclusive") if len(v) > 1 else (v[0], v[0], v[0])
    r = {"n": len(v), "median": statistics.median(v), "min": v[0], "max": v[-1], "q1": q1, "q3": q3, "iqr": q3 - q1}
    return {k: (x if k == "n" else round(x, 3)) for k, x in r.items()}


def round_medians(runs):
    """{round: the median seconds of the runs in it}."""
    out = {}
    for r in runs:
        out.setdefault(r["round"], []).append(r["seconds"])
    return {k: statistics.median(v) for k, v in out.items()}


def round_speedups(mitsuba_runs, pathbench_runs):
    """Per round: the median of Mitsuba's renders in it over the median of pathbench's in it,
    rounds where both rendered; the range of these is the ratio's spread."""
    m, p = round_medians(mitsuba_runs), round_medians(pathbench_runs)
    return [round(m[k] / p[k], 3) for k in sorted(m.keys() & p.keys()) if p[k] > 0]


def add_speedups(res):
    """Each pathbench entry's speed-up over Mitsuba: the ratio of the medians, and its range over rounds."""
    m = res["mitsuba"]
    for r in res["pathbench"].values():
        r["speedup_vs_mitsuba"] = round(m["median_seconds"] / r["median_seconds"], 3)
        per_round = round_speedups(m.get("runs", []), r.get("runs", []))
        r["speedup_by_round"] = per_round
        r["speedup_range"] = [min(per_round), max(per_round)] if per_round else None


def write_json(path: Path, obj):
    """Strict JSON (no NaN or Infinity: ValueError before anything is written), put in place
    atomically, so a failed run leaves no half-written file."""
    write_text_atomically(path, json.dumps(obj, indent=2, allow_nan=False) + "\n")


def layout_lines(pb, raw=False):
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
            + "`" + ("; the raw rates above come from the same choice" if raw else "") + "): " + "; ".join(parts) + "."]


def _timing_cells(r):
    s = r.get("spread") or spread(r["seconds"])
    return f"{s['median']:.2f} | {s['min']:.2f}–{s['max']:.2f} | {s['iqr']:.2f} | {s['n']}"


def _speedup_cell(ms_med, r):
    rng = r.get("speedup_range")
    return f"{ms_med / r['median_seconds']:.2f}x" + (f" ({rng[0]:.2f}–{rng[1]:.2f}x)" if rng else "")


def _raw_lines(raw, pb):
    lines = ["", "Against Embree's raw ray-cast rate for each render's own ray mix (camera rays as coherent "
             "closest hits, bounce rays as incoherent closest hits, shadow rays as incoherent occlusion rays; "
             "pathbench-bench raycast benchmarks on this scene, run once per round, medians; aim: 80%):", "",
             "| run | rays by kind (camera / bounce / shadow) | Embree calls | raw rate, same mix | "
             "pathbench rays/s | share of raw |", "|---|---|---|---:|---:|---:|"]
    for strategy, m_ in raw["mix"].items():
        r = pb[strategy]
        lines.append(f"| {strategy} | {r['rays']['camera'] / 1e6:.1f} M / {r['rays']['bounce'] / 1e6:.1f} M / "
                     f"{r['rays']['shadow'] / 1e6:.1f} M | {m_['calls']} | {m_['raw_rays_per_second'] / 1e6:.1f} M "
                     f"| {r['median_rays_per_second'] / 1e6:.1f} M | {100 * m_['share']:.0f}% |")
    return lines + ["", "Raw rates (M rays/s): " + ", ".join(
        f"{n.replace('raycast/cpu/', '').replace('/paper-cornell/real_time', '')} {v / 1e6:.1f}"
        for n, v in sorted(raw["rates"].items())) + "."]


def markdown(res):
    m, pb = res["mitsuba"], res["pathbench"]
    spp, px = res["settings"]["spp"], res["settings"]["width"] * res["settings"]["height"]
    em = res.get("emulation")
    threads = res["machine"]["hardware_threads"]
    lines = [
        f"# Mitsuba 3 vs pathbench on {res['machine']['cpu']}"
        + (f", emulating an {em['isa'].upper()}-only host" if em else ""),
        "",
        f"paper-cornell, {res['settings']['width']}x{res['settings']['height']}, {spp} spp, two bounces "
        "(Mitsuba `path` max_depth 3; pathbench `--bounces 2 --sampling nee`), box filter, "
        f"{threads} hardware threads, measured {res['date']} "
        f"(load average before {res['load_average_before']}, after {res['load_average_after']}"
        + (f"; {res['settings']['rounds']} interleaved rounds" if "rounds" in res["settings"] else "") + ").",
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
    if load > 0.5 * threads:
        lines += ["",
                  f"**The machine was busy** (1-minute load average {load} before the run, on "
                  f"{threads} hardware threads): every render was slowed. The renderers ran "
                  "in interleaved rounds, so the ratio is the informative number; absolute times are not."]
    lines += [
        "",
        "| renderer | median s | min–max s | IQR s | renders | samples/s | rays/s | speed-up over Mitsuba "
        "(range over rounds) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    ms_med = m["median_seconds"]
    lines.append(f"| {m['renderer']} {m['variant']} | {_timing_cells(m)} "
                 f"| {px * spp / ms_med / 1e6:.2f} M | ~{m['estimated_rays_per_second'] / 1e6:.1f} M (estimate) | 1.00x |")
    for strategy, r in pb.items():
        lines.append(f"| pathbench cpu/{strategy} | {_timing_cells(r)} | {px * spp / r['median_seconds'] / 1e6:.2f} M "
                     f"| {r['median_rays_per_second'] / 1e6:.1f} M | {_speedup_cell(ms_med, r)} |")
    if res.get("raw_embree"):
        lines += _raw_lines(res["raw_embree"], pb)
    first = next(iter(pb.values()))
    lines += [
        "",
        f"Mitsuba's warm-up render (JIT compilation, excluded): {m['warmup_seconds']:.2f} s.",
        f"Mitsuba rays/s is an estimate: its samples/s x {m['rays_per_sample_assumed']:.3f} rays per sample, what "
        "pathbench measured for this estimator when it traced every segment (Mitsuba does not count rays). pathbench "
        "now answers the last continuation ray with an emitter test and traces fewer rays per sample (rays/s counts "
        "only rays traced). `no-watertight`: Embree without its robust mode (faster; rays can slip through edges).",
        f"Image means (R, G, B): Mitsuba {m['image_mean_rgb']}, pathbench {first['image_mean_rgb']}.",
        *layout_lines(pb, bool(res.get("raw_embree"))),
        f"pathbench revision {first['git_revision']}, {first['compiler']}.",
        "",
        "Re-run: `.venv/bin/python tools/mitsuba_speed.py"
        + (f" --emulate-isa {em['isa']}" if em else "") + "` (after `scripts/build.sh`).",
        "",
    ]
    return "\n".join(lines)
