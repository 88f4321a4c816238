#!/usr/bin/env python3
"""The paper's Cornell box (pathbench's built-in `paper-cornell`) as a Mitsuba 3 scene,
and the `cornell-box` variants with mirrors, glass and rough metal
(tools/mitsuba_cornell_box.py; --scene cornell-box:ggx, say).

An independent renderer for the same scene: ../shared/paper-scene.md gives it exactly
and common/src/scenes/paper_cornell.cpp builds it for pathbench. Mitsuba's `path`
integrator with max_depth = 3 is pathbench's `--bounces 2 --sampling nee` estimator
(light sampling + BSDF sampling combined by MIS): the longest path is camera -> first
hit -> second hit -> light.

    .venv/bin/python tools/mitsuba_scene.py --out mitsuba.pfm --spp 64   # one render
    .venv/bin/python tools/mitsuba_scene.py --xml DIR                    # scene.xml + PLY

The geometry and camera below are plain data (no Mitsuba needed), so tests can check
them; scene_dict() turns them into a Mitsuba scene. Orientation: Mitsuba's image has
row 0 at the top and the red wall (x = -10) on the left, as pathbench's does (checked
by tests/python/test_mitsuba_scene.py against a pathbench render).

The llvm_ad_* variants need libLLVM; on Debian 12: apt-get install libllvm19. This
module points DRJIT_LIBLLVM_PATH at it when that file exists and the variable is unset.
"""
from __future__ import annotations

import argparse
import math
import os
import struct
import sys
from pathlib import Path

# ---- The scene, exactly as ../shared/paper-scene.md -------------------------------

VERTICES = [
    (-10, -10, 22), (-10, -10, -10), (-10, 10, -10), (-10, 10, 22),   # 0..3
    (10, -10, 22), (10, -10, -10), (10, 10, -10), (10, 10, 22),       # 4..7
    (-5, 9.9, -8), (-5, 9.9, -2), (5, 9.9, -2), (5, 9.9, -8),         # 8..11: light
]

# (part name, triangles as vertex ids in the paper's order, albedo, emitted radiance)
PARTS = [
    ("left", [(0, 1, 2), (0, 2, 3)], (0.5, 0.0, 0.0), None),
    ("back", [(1, 5, 6), (1, 6, 2)], (0.5, 0.5, 0.5), None),
    ("right", [(5, 7, 6), (5, 4, 7)], (0.0, 0.5, 0.0), None),
    ("ceiling", [(2, 7, 3), (2, 6, 7)], (0.5, 0.5, 0.5), None),
    ("floor", [(0, 5, 1), (0, 4, 5)], (0.5, 0.5, 0.5), None),
    ("front", [(0, 7, 3), (0, 4, 7)], (0.5, 0.5, 0.5), None),
    ("light", [(10, 9, 8), (11, 10, 8)], (0.0, 0.0, 0.0), (10.0, 10.0, 10.0)),
]

CAMERA_ORIGIN = (0.0, 0.0, 20.0)
CAMERA_TARGET = (0.0, 0.0, 0.0)
CAMERA_UP = (0.0, 1.0, 0.0)
FOV_DEG = 2.0 * math.degrees(math.atan(10.5 / 19.0))  # full field of view, both axes

WIDTH = HEIGHT = 256
MAX_DEPTH = 3  # Mitsuba counts segments: 3 = two diffuse bounces = pathbench --bounces 2

LLVM_DEFAULT = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"

# Largest PFM image read_pfm reads: pathbench's own image limit (limits.h kMaxPixels).
MAX_PFM_PIXELS = 1 << 28


def triangle_count() -> int:
    return sum(len(tris) for _, tris, _, _ in PARTS)


def part_mesh(tris):
    """A part's own vertex list (so no vertex is shared between walls) and faces."""
    ids = sorted({v for t in tris for v in t})
    remap = {v: i for i, v in enumerate(ids)}
    verts = [VERTICES[v] for v in ids]
    faces = [tuple(remap[v] for v in t) for t in tris]
    return verts, faces


# ---- Mitsuba ----------------------------------------------------------------------

def import_mitsuba(variant: str):
    """Imports mitsuba and sets `variant`; for llvm variants sets DRJIT_LIBLLVM_PATH."""
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM_DEFAULT):
        os.environ["DRJIT_LIBLLVM_PATH"] = LLVM_DEFAULT
    import mitsuba as mi  # noqa: PLC0415 (optional dependency)

    mi.set_variant(variant)
    return mi


def _bsdf(albedo):
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(albedo)}}


def _mesh(mi, name, verts, faces, bsdf, emitter):
    import numpy as np  # noqa: PLC0415

    props = mi.Properties()
    props["bsdf"] = mi.load_dict(bsdf)
    props["face_normals"] = True
    if emitter is not None:
        props["emitter"] = mi.load_dict(emitter)
    mesh = mi.Mesh(name, len(verts), len(faces), props=props, has_vertex_normals=False)
    params = mi.traverse(mesh)
    params["vertex_positions"] = np.asarray(verts, dtype=np.float32).ravel()
    params["faces"] = np.asarray(faces, dtype=np.uint32).ravel()
    params.update()
    return mesh


def sensor_dict(mi, width=WIDTH, height=HEIGHT, spp=64, seed=0):
    return {
        "type": "perspective",
        "fov": FOV_DEG,
        "fov_axis": "y",
        "near_clip": 0.01,
        "far_clip": 1000.0,
        "to_world": mi.ScalarTransform4f().look_at(origin=CAMERA_ORIGIN, target=CAMERA_TARGET, up=CAMERA_UP),
        "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        "film": {
            "type": "hdrfilm",
            "width": width,
            "height": height,
            "rfilter": {"type": "box"},  # radius 0.5: a sample counts only in its own pixel
            "pixel_format": "rgb",
            "component_format": "float32",
        },
    }


def material_bsdf(m):
    """pathbench material (tools/mitsuba_cornell_box.py's dicts) -> Mitsuba BSDF dict,
    each the plugin pathbench's BSDF of that kind is defined as (common/bsdf/)."""
    rgb = lambda c: {"type": "rgb", "value": list(c)}  # noqa: E731
    kind = m.get("kind", "diffuse")
    if m.get("emission") is not None:
        # Emitters: one-sided, and (in pathbench's scenes) black, as paper-cornell's light.
        if any(m["albedo"]) or kind != "diffuse":
            raise ValueError("only black diffuse emitters are exported")
        return _bsdf((0.0, 0.0, 0.0))
    if kind == "diffuse":
        return {"type": "twosided", "material": _bsdf(m["albedo"])}
    if kind == "mirror":
        return {"type": "twosided", "material": {"type": "conductor", "material": "none",
                                                 "specular_reflectance": rgb(m["albedo"])}}
    if kind == "dielectric":  # two-sided by nature: entering from the front, leaving from the back
        return {"type": "dielectric", "int_ior": float(m["ior"]), "ext_ior": 1.0,
                "specular_reflectance": rgb(m["albedo"]), "specular_transmittance": rgb(m["albedo"])}
    if kind == "roughconductor":
        return {"type": "twosided", "material": {"type": "roughconductor", "distribution": "ggx",
                                                 "alpha": float(m["alpha"]), "material": "none",
                                                 "specular_reflectance": rgb(m["albedo"])}}
    raise ValueError(f"unknown material kind {kind}")


def _integrator(max_depth):
    # Russian roulette starts after max_depth, i.e. never: pathbench --bounces N has none.
    return {"type": "path", "max_depth": max_depth, "rr_depth": max(max_depth, 1) + 100, "hide_emitters": False}


def cornell_box_dict(mi, variant="", width=WIDTH, height=HEIGHT, spp=64, seed=0, max_depth=MAX_DEPTH):
    """pathbench's `cornell-box[:variant]` (tools/mitsuba_cornell_box.py) for mi.load_dict."""
    import mitsuba_cornell_box as cb  # noqa: PLC0415

    origin, target, up, fov = cb.CAMERA
    sensor = sensor_dict(mi, width, height, spp, seed)
    sensor["fov"] = fov
    sensor["near_clip"], sensor["far_clip"] = 1.0, 1e5  # millimetres: the back wall is 1.36 m away
    sensor["to_world"] = mi.ScalarTransform4f().look_at(origin=origin, target=target, up=up)
    d = {"type": "scene", "integrator": _integrator(max_depth), "sensor": sensor}
    for name, verts, faces, m in cb.parts(variant):
        emitter = None
        if m.get("emission") is not None:
            emitter = {"type": "area", "radiance": {"type": "rgb", "value": list(m["emission"])}}
        d[name] = _mesh(mi, name, verts, faces, material_bsdf(m), emitter)
    return d


def scene_dict(mi, width=WIDTH, height=HEIGHT, spp=64, seed=0, max_depth=MAX_DEPTH, scene="paper-cornell"):
    """The Mitsuba scene description (a dict for mi.load_dict): paper-cornell (this
    file's data), or cornell-box / cornell-box:VARIANT."""
    if scene.startswith("cornell-box"):
        variant = scene.split(":", 1)[1] if ":" in scene else ""
        return cornell_box_dict(mi, variant, width, height, spp, seed, max_depth)
    if scene != "paper-cornell":
        raise ValueError(f"no Mitsuba version of scene '{scene}' (paper-cornell, cornell-box[:variant])")
    d = {
        "type": "scene",
        "integrator": _integrator(max_depth),
        "sensor": sensor_dict(mi, width, height, spp, seed),
    }
    for name, tris, albedo, emission in PARTS:
        verts, faces = part_mesh(tris)
        if emission is None:
            # Two-sided Lambertian: the front wall faces out of the box, the others in.
            bsdf = {"type": "twosided", "material": _bsdf(albedo)}
            emitter = None
        else:
            # One-sided emitter on the side of the geometric normal (0, -1, 0); it
            # does not reflect (a black BSDF).
            bsdf = _bsdf((0.0, 0.0, 0.0))
            emitter = {"type": "area", "radiance": {"type": "rgb", "value": list(emission)}}
        d[name] = _mesh(mi, name, verts, faces, bsdf, emitter)
    return d


def load_scene(mi, **kw):
    return mi.load_dict(scene_dict(mi, **kw))


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


def write_xml(outdir, spp=64, width=WIDTH, height=HEIGHT):
    """scene.xml and one binary PLY per part, for Mitsuba's command-line renderer."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    shapes = []
    for name, tris, albedo, emission in PARTS:
        verts, faces = part_mesh(tris)
        with open(outdir / f"{name}.ply", "wb") as f:
            f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\n"
                     "property float x\nproperty float y\nproperty float z\n"
                     f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
            for v in verts:
                f.write(struct.pack("<3f", *v))
            for t in faces:
                f.write(struct.pack("<B3i", 3, *t))
        rgb = lambda c: ", ".join(f"{x:g}" for x in c)  # noqa: E731
        if emission is None:
            inner = (f'<bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="{rgb(albedo)}"/>'
                     "</bsdf></bsdf>")
        else:
            inner = ('<bsdf type="diffuse"><rgb name="reflectance" value="0, 0, 0"/></bsdf>'
                     f'<emitter type="area"><rgb name="radiance" value="{rgb(emission)}"/></emitter>')
        shapes.append(f'  <shape type="ply" id="{name}"><string name="filename" value="{name}.ply"/>'
                      f'<boolean name="face_normals" value="true"/>{inner}</shape>')
    o, t, u = (", ".join(f"{x:g}" for x in v) for v in (CAMERA_ORIGIN, CAMERA_TARGET, CAMERA_UP))
    xml = f"""<?xml version="1.0"?>
<!-- pathbench paper-cornell, written by tools/mitsuba_scene.py (option xml) -->
<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="{MAX_DEPTH}"/><integer name="rr_depth" value="{MAX_DEPTH + 100}"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="{FOV_DEG!r}"/><string name="fov_axis" value="y"/>
    <transform name="to_world"><lookat origin="{o}" target="{t}" up="{u}"/></transform>
    <sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>
    <film type="hdrfilm"><integer name="width" value="{width}"/><integer name="height" value="{height}"/>
      <rfilter type="box"/><string name="pixel_format" value="rgb"/></film>
  </sensor>
{chr(10).join(shapes)}
</scene>
"""
    (outdir / "scene.xml").write_text(xml)
    return outdir / "scene.xml"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (scalar_rgb needs no LLVM)")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--size", type=int, default=WIDTH, help="width = height")
    ap.add_argument("--max-depth", type=int, default=MAX_DEPTH)
    ap.add_argument("--scene", default="paper-cornell", help="paper-cornell or cornell-box[:mirror|glass|spheres|ggx]"
                    " (--xml writes paper-cornell only)")
    ap.add_argument("--out", help="render to this .pfm")
    ap.add_argument("--xml", help="write scene.xml and PLY meshes into this folder")
    a = ap.parse_args(argv)
    if a.xml:
        print(write_xml(a.xml, spp=a.spp, width=a.size, height=a.size))
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
