#!/usr/bin/env python3
"""Independent reference image of paper-cornell (2 bounces, light sampling + MIS)
from Mitsuba 3, with a per-pixel variance of the mean, for the statistical image
test (tests/unit/test_statistical_render.cpp); with --scene cornell-box:VARIANT
--bounces N, of a cornell-box material variant (tests/unit/test_materials_reference.cpp).

    .venv/bin/python tools/make_reference.py            # 32 passes x 512 spp (~20 min on 2 cores)
    .venv/bin/python tools/make_reference.py --passes 8 --spp 64 --out-dir /tmp/ref   # quick

Renders K independent passes (Mitsuba seeds 0 .. K-1) of the scene as pathbench exports
it (tools/mitsuba_scene.py), then writes
    <out-dir>/<scene>-nee-ref.pfm       per-pixel mean over the passes (RGB float)
    <out-dir>/<scene>-nee-ref-var.pfm   variance of that mean: sample variance of
                                         the pass images / K
    <out-dir>/<scene>-nee-ref.json      how it was made
(<scene> with ':' as '-', e.g. cornell-box-ggx).
Each pass is kept in --cache as it finishes, so an interrupted run resumes.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mitsuba_scene as ms  # noqa: E402
from machine import slugify  # noqa: E402
from machine import cpu_model  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def reference_from_passes(passes: np.ndarray):
    """(K, H, W, 3) pass images -> (mean, variance of the mean), float64."""
    k = passes.shape[0]
    if k < 2:
        raise ValueError("need at least two passes for a variance")
    mean = passes.mean(axis=0, dtype=np.float64)
    var_of_mean = passes.var(axis=0, ddof=1, dtype=np.float64) / k
    return mean, var_of_mean


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--passes", type=int, default=32)
    ap.add_argument("--spp", type=int, default=512, help="samples per pixel per pass")
    ap.add_argument("--size", type=int, default=ms.WIDTH)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--scene", default="paper-cornell", help="paper-cornell or cornell-box[:VARIANT] (mitsuba_scene.py)")
    ap.add_argument("--bounces", type=int, default=ms.MAX_DEPTH - 1, help="pathbench --bounces (max_depth - 1)")
    ap.add_argument("--out-dir", default=str(ROOT / "tests" / "data"))
    ap.add_argument("--cache", default=str(ROOT / "out" / "mitsuba-ref-passes"))
    a = ap.parse_args(argv)

    mi = ms.import_mitsuba(a.variant)
    max_depth = a.bounces + 1
    scene = ms.load_scene(mi, width=a.size, height=a.size, spp=a.spp, max_depth=max_depth, scene=a.scene)
    cache = Path(a.cache)
    cache.mkdir(parents=True, exist_ok=True)
    slug = slugify(a.scene, "scene")  # "cornell-box:ggx" -> "cornell-box-ggx", as pb::slugify
    tag = f"{a.variant}-{a.size}-{a.spp}spp"
    if a.scene != "paper-cornell" or max_depth != ms.MAX_DEPTH:
        tag = f"{slug}-depth{max_depth}-{tag}"
    images, seconds = [], 0.0
    for k in range(a.passes):
        f = cache / f"{tag}-seed{k}.npy"
        if f.exists():
            images.append(np.load(f))
            continue
        t0 = time.perf_counter()
        img = ms.render(mi, scene, a.spp, seed=k)
        dt = time.perf_counter() - t0
        seconds += dt
        np.save(f, img)
        images.append(img)
        print(f"pass {k + 1}/{a.passes}: seed {k}, {dt:.1f} s, mean {img.reshape(-1, 3).mean(axis=0)}", flush=True)

    mean, var = reference_from_passes(np.stack(images))
    out = Path(a.out_dir)
    stem = f"{slug}-nee-ref"
    ms.write_pfm(out / f"{stem}.pfm", mean.astype(np.float32))
    ms.write_pfm(out / f"{stem}-var.pfm", var.astype(np.float32))
    meta = {
        "scene": a.scene,
        "renderer": f"Mitsuba {mi.__version__}, variant {a.variant}",
        "integrator": f"path, max_depth {max_depth} (pathbench --bounces {a.bounces} --sampling nee)",
        "width": a.size,
        "height": a.size,
        "passes": a.passes,
        "spp_per_pass": a.spp,
        "spp_total": a.passes * a.spp,
        "seeds": f"0..{a.passes - 1}",
        "image_mean_rgb": [float(x) for x in mean.reshape(-1, 3).mean(axis=0)],
        "median_relative_std_error": float(np.median(np.sqrt(var) / np.maximum(mean, 1e-6))),
        "render_seconds_this_run": round(seconds, 1),
        "machine": cpu_model(),
        "made_by": "tools/make_reference.py " + " ".join(argv if argv is not None else sys.argv[1:]),
    }
    (out / f"{stem}.json").write_text(json.dumps(meta, indent=2) + "\n")
    print(json.dumps(meta, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
