#!/usr/bin/env python3
"""FLIP, the Markdown table and the plots of a `pathbench accuracy` run.

`pathbench accuracy` renders and computes the numeric metrics (RMSE, relative MSE,
bias with its standard error, efficiency) into <out-dir>/<scene>-<W>x<H>-<device>.json
and runs this tool on it when the project's .venv is there. Alone:

    .venv/bin/python tools/accuracy_report.py results/amd-epyc/accuracy/paper-cornell-128x128-cpu.json

It adds to the JSON each row's mean FLIP error against the reference, then writes
beside it (same stem):
    <stem>.md                 the table: a summary per configuration and every row
    <stem>-error-vs-time.png  relative MSE against render time, log-log, one line per
                              configuration, one panel per comparison
    <stem>-flip-vs-time.png   the same for FLIP
    <stem>-bias.png           bias against the reference with 2-sigma error bars
    <stem>-reference.png      the reference, tonemapped as FLIP sees it

FLIP: LDR-FLIP (Andersson et al. 2020, the `flip-evaluator` package, default 67
pixels per degree) on both images tonemapped the same way: clamped to [0, 1] and
sRGB-encoded, as the PNGs pathbench writes. Per-render images come from the run's
images/ folder, which is not committed: FLIP can be recomputed only where the run was.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mitsuba_scene import read_pfm  # noqa: E402  (plain PFM reader; needs no Mitsuba)

# Panels and table sections, in this order; a configuration may be in several.
GROUPS = {
    "bounces": "Bounce budget (nee; unbounded = Russian roulette)",
    "sampling": "Sampling (unbounded + RR)",
    "roulette": "Russian roulette at 8 bounces",
    "precision": "Path-step precision",
    "intersection": "Ray/triangle test",
    "paper": "The paper's estimator",
}


def tonemap_srgb(img: np.ndarray) -> np.ndarray:
    """Linear RGB -> [0, 1] sRGB-encoded (clamp, then the sRGB transfer curve)."""
    x = np.clip(np.asarray(img, dtype=np.float32), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055).astype(np.float32)


def flip_mean(reference: np.ndarray, test: np.ndarray) -> float:
    """Mean LDR-FLIP error of `test` against `reference` (both linear RGB, HxWx3)."""
    import flip_evaluator as flip  # noqa: PLC0415

    _, mean, _ = flip.evaluate(tonemap_srgb(reference), tonemap_srgb(test), "LDR", inputsRGB=True,
                               applyMagma=False)
    return float(mean)


def seconds_to_reach(rows: list[dict], key: str, target: float) -> float | None:
    """Render time at which `key` falls to `target`, interpolated log-log between the
    ladder's rungs; None if the ladder never gets there (or starts below it)."""
    pts = [(r["seconds"], r[key]) for r in rows if r.get(key) is not None and r["seconds"] > 0 and r[key] > 0]
    pts.sort()
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 >= target >= e1 and e0 != e1:
            f = (math.log(e0) - math.log(target)) / (math.log(e0) - math.log(e1))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None


def fmt_num(v, spec: str) -> str:
    return "" if v is None else format(v, spec)


def fmt_bias(r: dict) -> str:
    s = f"{100 * r['bias']:+.2f}%"
    if r.get("bias_stderr") is not None:
        s += f" ± {100 * r['bias_stderr']:.2f}%"
    return s


def fmt_z(r: dict) -> str:
    z = r.get("bias_z")
    if z is None:
        return ""
    return f"{z:+.1f}" + (" **biased**" if r.get("biased") else "")


def rows_of(res: dict, name: str) -> list[dict]:
    return sorted((r for r in res["rows"] if r["config"] == name), key=lambda r: r["spp"])


def markdown(res: dict, stem: str) -> str:
    cfgs = {c["name"]: c for c in res["configurations"]}
    ref = res["reference"]
    m = res["metrics"]
    target = 1e-2
    out = [f"# Speed against accuracy: {res['scene']}, {res['width']}x{res['height']}, {res['device']}/{res['strategy']}",
           ""]
    out.append(f"![relative MSE against time]({stem}-error-vs-time.png)")
    if any(r.get("flip") is not None for r in res["rows"]):
        out.append(f"![FLIP against time]({stem}-flip-vs-time.png)")
    out.append(f"![bias]({stem}-bias.png)")
    out.append("")
    out.append("## Summary: the last rung of each configuration's ladder")
    out.append("")
    out.append(f"| configuration | spp | seconds | M rays/s | relMSE | FLIP | bias ± std. error | z | efficiency "
               f"| seconds to relMSE {target:g} |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, c in cfgs.items():
        rows = rows_of(res, name)
        if not rows:
            continue
        r = rows[-1]
        t = seconds_to_reach(rows, "rel_mse", target)
        out.append(f"| {c['label']} | {r['spp']} | {r['seconds']:.3f} | {r['rays_per_second'] / 1e6:.1f} "
                   f"| {r['rel_mse']:.3e} | {fmt_num(r.get('flip'), '.4f')} | {fmt_bias(r)} | {fmt_z(r)} "
                   f"| {fmt_num(r.get('efficiency'), '.3g')} | {fmt_num(t, '.3g') or 'not reached'} |")
    for s in res.get("skipped", []):
        out.append(f"| {cfgs.get(s['config'], {}).get('label', s['config'])} | skipped: {s['reason']} "
                   "| | | | | | | | |")
    out.append("")
    for group, title in GROUPS.items():
        names = [n for n, c in cfgs.items() if group in c["groups"] and rows_of(res, n)]
        if not names:
            continue
        out.append(f"## {title}")
        out.append("")
        out.append("| configuration | spp | seconds | rays | RMSE | relMSE | FLIP | bias ± std. error | z | efficiency |")
        out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for n in names:
            for r in rows_of(res, n):
                out.append(f"| {cfgs[n]['label']} | {r['spp']} | {r['seconds']:.4f} | {r['rays']} | {r['rmse']:.4g} "
                           f"| {r['rel_mse']:.4g} | {fmt_num(r.get('flip'), '.4f')} | {fmt_bias(r)} | {fmt_z(r)} "
                           f"| {fmt_num(r.get('efficiency'), '.4g')} |")
        out.append("")
    load0, load1 = res.get("load_average_at_start"), res.get("load_average_at_end")
    out.append("## How it was measured")
    out.append("")
    out.append(f"- Reference: {ref['spp']} spp, the best estimator the tracer has (unbounded paths ended by Russian "
               f"roulette, light sampling + MIS, watertight, {ref.get('precision', 'double')} precision), "
               f"its own seed; {'loaded from the cache' if ref.get('cached') else 'rendered for this run'} "
               f"({ref['file']}, {ref.get('seconds', 0):.1f} s when rendered). Its own noise adds "
               f"{ref['rel_mse_floor']:.2e} to every relative MSE (the floor, dashed in the plot).")
    out.append(f"- Each configuration renders at 1, 4, 16, ... spp (x{res['ladder']['factor']}; rung by rung, every "
               "configuration's rung in turn, so changing load touches all alike) up to "
               f"{res['ladder']['max_spp']} spp, stopping before a render expected to take over "
               f"{res['ladder']['max_seconds']:g} s. Seconds: {m['seconds']}. Every render also accumulates the "
               "per-pixel variance (for the bias's standard error), which costs the same in every configuration.")
    out.append(f"- RMSE: {m['rmse']}. relMSE: {m['rel_mse']}. FLIP: mean LDR-FLIP (flip-evaluator, 67 ppd) of both "
               "images clamped to [0, 1] and sRGB-encoded. Efficiency: " + m["efficiency"] + ".")
    out.append(f"- Bias: {m['bias']}. z = bias / std. error; |z| > {m['bias_z_threshold']:g} is marked **biased** "
               "(a difference that noise does not explain); at a few spp the image mean's distribution is skewed by "
               "rare bright paths, so z is a rough guide there. Every configuration uses the same seed, so their "
               "noise is correlated and differences between them are resolved better than each one's error bar "
               "suggests. Bounded bounce budgets lose the light of longer paths: "
               "their bias is negative and stays as spp grows, while their noise falls.")
    if res["device"] == "gpu":
        out.append("- Intersection (GPU): `watertight` is the watertight ray/triangle test of Woop, Benthin & Wald "
                   "2013 (common/watertight.h); `moller-trumbore` is the Möller–Trumbore test, the paper's.")
    else:
        out.append("- Intersection: `watertight` is Embree 3's robust mode (RTC_SCENE_FLAG_ROBUST: the Plücker test "
                   "of triangle_intersector_pluecker.h, watertight along shared edges, with conservative traversal); "
                   "`moller-trumbore` is its default fast mode (triangle_intersector_moeller.h), the paper's test.")
    out.append("- "
               "Precision: the path step (camera ray, surface_hit, shading, sampling) runs in float or double; the "
               "intersector finds the hit triangle in float either way and surface_hit recomputes the hit point in "
               "the path step's type.")
    mach = res["machine"]
    gpu = mach.get("gpu", {}).get("name")
    device = f"GPU {gpu}" if gpu else f"CPU, {mach.get('threads', '?')} threads"
    out.append(f"- Machine: {mach['cpu']} ({mach['hardware_threads']} hardware threads); ran on {device}; "
               f"git {res['git_revision']}, {res['compiler']}; {res['date']}. Load average at start "
               f"{load0}, at end {load1}: on a shared machine other work slows some renders, so times (and "
               "efficiencies) carry that noise; the errors do not.")
    out.append("")
    return "\n".join(out)


def _panels(plt, n: int):
    """A figure with one panel per comparison, three to a row; unused panels hidden."""
    cols = min(3, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(5.0 * cols, 3.9 * rows), squeeze=False)
    flat = [ax for row in axes for ax in row]
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]


def plot(res: dict, out_stem: Path) -> list[Path]:
    """error-vs-time (relative MSE), flip-vs-time (if FLIP is there) and bias PNGs."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    from matplotlib.ticker import NullFormatter  # noqa: PLC0415

    cfgs = {c["name"]: c for c in res["configurations"]}
    groups = [g for g in GROUPS if any(g in c["groups"] and rows_of(res, n) for n, c in cfgs.items())]
    colors = {n: plt.cm.tab20(i % 20) for i, n in enumerate(cfgs)}
    title = f"{res['scene']} {res['width']}x{res['height']}, {res['device']}"
    written = []

    def series(g, key):
        for n, c in cfgs.items():
            rows = [r for r in rows_of(res, n) if r.get(key) is not None]
            if g in c["groups"] and rows:
                yield n, c, rows

    plots = [("rel_mse", "relative MSE", "error-vs-time")]
    if any(r.get("flip") is not None for r in res["rows"]):
        plots.append(("flip", "mean FLIP (LDR)", "flip-vs-time"))
    for key, label, suffix in plots:
        fig, axes = _panels(plt, len(groups))
        for ax, g in zip(axes, groups):
            for n, c, rows in series(g, key):
                ax.loglog([r["seconds"] for r in rows], [r[key] for r in rows], "o-", ms=3, color=colors[n],
                          label=c["label"])
            if key == "rel_mse":
                ax.axhline(res["reference"]["rel_mse_floor"], color="grey", ls="--", lw=0.8, label="reference floor")
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel("render time (s)")
            ax.set_ylabel(label)
            ax.set_title(GROUPS[g], fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
        fig.suptitle(f"{label} against render time (log-log): {title}")
        fig.tight_layout()
        png = out_stem.with_name(f"{out_stem.name}-{suffix}.png")
        fig.savefig(png, dpi=100)
        plt.close(fig)
        written.append(png)

    fig, axes = _panels(plt, len(groups))
    for ax, g in zip(axes, groups):
        for n, c, rows in series(g, "bias_stderr"):
            ax.errorbar([r["spp"] for r in rows], [100 * r["bias"] for r in rows],
                        yerr=[200 * r["bias_stderr"] for r in rows], fmt="o-", ms=3, capsize=2, color=colors[n],
                        label=c["label"])
        ax.axhline(0, color="black", lw=0.8)
        ax.set_xscale("log", base=2)
        ax.set_xlabel("samples per pixel")
        ax.set_ylabel("image mean vs reference (%)")
        ax.set_title(GROUPS[g], fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"Bias against the reference, error bars 2 standard errors: {title}")
    fig.tight_layout()
    png = out_stem.with_name(out_stem.name + "-bias.png")
    fig.savefig(png, dpi=100)
    plt.close(fig)
    written.append(png)
    return written


def add_flip(res: dict, run_dir: Path, reference: np.ndarray) -> int:
    """Adds 'flip' to every row whose image is there; returns how many it could not."""
    missing = 0
    for r in res["rows"]:
        img = run_dir / r["image"]
        if not img.exists():
            missing += 1
            continue
        r["flip"] = flip_mean(reference, read_pfm(img))
    return missing


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("json", help="the run's JSON, written by `pathbench accuracy`")
    ap.add_argument("--no-flip", action="store_true", help="keep the JSON's FLIP values (or none); plots and table only")
    a = ap.parse_args(argv)
    path = Path(a.json)
    res = json.loads(path.read_text())
    run_dir = path.parent
    stem = path.stem
    reference = read_pfm(run_dir / res["reference"]["file"])
    if not a.no_flip:
        missing = add_flip(res, run_dir, reference)
        res["metrics"]["flip"] = ("mean LDR-FLIP (flip-evaluator, 67 ppd) of both images clamped to [0, 1] and "
                                  "sRGB-encoded")
        if missing:
            print(f"accuracy_report: {missing} row images not found under {run_dir}; their FLIP is left out",
                  file=sys.stderr)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps(res, indent=2) + "\n")
        tmp.replace(path)
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    plt.imsave(run_dir / f"{stem}-reference.png", tonemap_srgb(reference))
    pngs = plot(res, run_dir / stem)
    md = run_dir / f"{stem}.md"
    md.write_text(markdown(res, stem))
    print(f"accuracy_report: {md}, " + ", ".join(str(p) for p in pngs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
