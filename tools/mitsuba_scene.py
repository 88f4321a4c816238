#!/usr/bin/env python3
"""pathbench's scenes as Mitsuba 3 scenes, for the accuracy references, crosscheck and
mitsuba_speed: `paper-cornell` (the 2015 paper's Cornell box), `cornell-box[:VARIANT]`
with mirrors, glass and rough metal, or any scene pathbench loads.

The scene is not rebuilt here: pathbench exports it (the Python module's export_mitsuba,
the one Mitsuba exporter, scene_io/src/mitsuba_export.cpp beside the Mitsuba XML reader),
so its geometry, camera and material mapping are defined once, in pathbench. Mitsuba's
`path` integrator with max_depth = 3 is pathbench's `--bounces 2 --sampling nee` estimator
(light sampling + BSDF sampling combined by MIS): the longest path is camera -> first
hit -> second hit -> light.

    .venv/bin/python tools/mitsuba_scene.py --out mitsuba.pfm --spp 64   # one render
    .venv/bin/python tools/mitsuba_scene.py --xml DIR                    # scene.xml + PLY

The pathbench module is the installed one, or the build tree's (build/python, or
$PATHBENCH_PYTHON_DIR). The llvm_ad_* variants need libLLVM; on Debian 12: apt-get install
libllvm19. This module points DRJIT_LIBLLVM_PATH at it when that file exists and the
variable is unset.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

WIDTH = HEIGHT = 256
MAX_DEPTH = 3  # Mitsuba counts segments: 3 = two diffuse bounces = pathbench --bounces 2

LLVM_DEFAULT = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"

# Largest PFM image read_pfm reads: pathbench's own image limit (limits.h kMaxPixels).
MAX_PFM_PIXELS = 1 << 28


def pathbench_module():
    """The `pathbench` Python module: installed, else the build tree's."""
    try:
        import pathbench  # noqa: PLC0415
    except ImportError:
        sys.path.insert(0, os.environ.get("PATHBENCH_PYTHON_DIR", str(ROOT / "build" / "python")))
        try:
            import pathbench  # noqa: PLC0415
        except ImportError as e:
            raise RuntimeError("the pathbench Python module is needed to export scenes to Mitsuba (scripts/build.sh "
                               "builds it into build/python; or pip install .)") from e
    return pathbench


def write_xml(outdir, scene="paper-cornell", width=WIDTH, height=HEIGHT, max_depth=MAX_DEPTH):
    """pathbench's export of `scene`: outdir/scene.xml and one PLY per material; returns its path.
    max_depth < 0: unbounded paths ended by Russian roulette (pathbench --converged)."""
    pb = pathbench_module()
    bounces = None if max_depth < 0 else max_depth - 1
    return Path(pb.export_mitsuba(pb.load_scene(scene), str(outdir), width, height, bounces=bounces,
                                  converged=max_depth < 0))


# ---- Mitsuba ----------------------------------------------------------------------

def import_mitsuba(variant: str):
    """Imports mitsuba and sets `variant`; for llvm variants sets DRJIT_LIBLLVM_PATH."""
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM_DEFAULT):
        os.environ["DRJIT_LIBLLVM_PATH"] = LLVM_DEFAULT
    import mitsuba as mi  # noqa: PLC0415 (optional dependency)

    mi.set_variant(variant)
    return mi


def load_scene(mi, width=WIDTH, height=HEIGHT, spp=64, seed=0, max_depth=MAX_DEPTH, scene="paper-cornell"):
    """`scene` as pathbench exports it, loaded into Mitsuba (spp and seed are given at
    render time: render())."""
    del spp, seed
    with tempfile.TemporaryDirectory(prefix="pathbench-mitsuba-") as d:
        return mi.load_file(str(write_xml(d, scene, width, height, max_depth)))


def render(mi, scene, spp, seed):
    """One render as a float32 numpy array (height, width, 3), row 0 at the top."""
    import numpy as np  # noqa: PLC0415

    img = mi.render(scene, spp=spp, seed=seed)
    return np.array(img, dtype=np.float32)[:, :, :3]


# ---- Files ------------------------------------------------------------------------

def write_pfm(path, img):
    """Little-endian RGB PFM; `img` is (height, width, 3), row 0 at the top."""
    import numpy as np  # noqa: PLC0415

    img = np.asarray(img, dtype="<f4")
    h, w, _ = img.shape
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(img[::-1]).tobytes())  # PFM stores the bottom row first
    tmp.replace(path)


def read_pfm(path):
    """Returns (height, width, 3) float32, row 0 at the top."""
    import numpy as np  # noqa: PLC0415

    with open(path, "rb") as f:
        kind = f.readline(16).strip()
        if kind not in (b"PF", b"Pf"):
            raise ValueError(f"{path}: not a PFM file")
        dims = f.readline(64).split()
        while len(dims) < 2:
            line = f.readline(64)
            if not line:
                raise ValueError(f"{path}: PFM header ends before its width and height")
            dims += line.split()
        try:
            w, h = int(dims[0]), int(dims[1])
            scale = float(f.readline(64))
        except ValueError:
            raise ValueError(f"{path}: malformed PFM header") from None
        ch = 3 if kind == b"PF" else 1
        # Sizes from the header are checked before they size anything: a header may claim
        # any size; the data must hold that many values.
        if w <= 0 or h <= 0 or w * h > MAX_PFM_PIXELS or not math.isfinite(scale) or scale == 0:
            raise ValueError(f"{path}: PFM header of {w}x{h} pixels, scale {scale} is not supported (1 to "
                             f"{MAX_PFM_PIXELS} pixels, a finite nonzero scale)")
        data = f.read(w * h * ch * 4)
        if len(data) != w * h * ch * 4:
            raise ValueError(f"{path}: PFM data is {len(data)} bytes, its header says {w * h * ch * 4}")
        data = np.frombuffer(data, dtype="<f4" if scale < 0 else ">f4", count=w * h * ch)
    img = data.reshape(h, w, ch)[::-1].astype(np.float32)
    if ch == 1:
        img = np.repeat(img, 3, axis=2)
    return img


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (scalar_rgb needs no LLVM)")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--size", type=int, default=WIDTH, help="width = height")
    ap.add_argument("--max-depth", type=int, default=MAX_DEPTH)
    ap.add_argument("--scene", default="paper-cornell", help="paper-cornell, cornell-box[:mirror|glass|spheres|ggx], "
                    "or any scene pathbench loads")
    ap.add_argument("--out", help="render to this .pfm")
    ap.add_argument("--xml", help="write scene.xml and PLY meshes into this folder")
    a = ap.parse_args(argv)
    if a.xml:
        print(write_xml(a.xml, a.scene, width=a.size, height=a.size, max_depth=a.max_depth))
    if a.out:
        mi = import_mitsuba(a.variant)
        scene = load_scene(mi, width=a.size, height=a.size, spp=a.spp, seed=a.seed, max_depth=a.max_depth,
                           scene=a.scene)
        img = render(mi, scene, a.spp, a.seed)
        write_pfm(a.out, img)
        print(f"{a.out}: mean RGB {img.reshape(-1, 3).mean(axis=0)}")
    if not (a.xml or a.out):
        ap.print_help()
    return 0


if __name__ == "__main__":
    sys.exit(main())
