"""pathbench's built-in `cornell-box` and its material variants, as plain data for
tools/mitsuba_scene.py: rebuilt here from the same published data
(common/src/scenes/cornell_box.cpp cites it) rather than read from pathbench, so a
Mitsuba render of it is an independent check of pathbench's materials.

parts(variant) -> [(name, vertices, faces, material)], material a dict:
    {"kind": "diffuse" | "mirror" | "dielectric" | "roughconductor",
     "albedo": (r, g, b), "emission": (r, g, b) or None, "ior": x, "alpha": x}
CAMERA: (origin, target, up, vertical fov in degrees).
"""
from __future__ import annotations

import math

import numpy as np

VARIANTS = ("", "mirror", "glass", "spheres", "ggx")

WHITE = {"kind": "diffuse", "albedo": (0.75, 0.75, 0.75)}
RED = {"kind": "diffuse", "albedo": (0.63, 0.065, 0.05)}
GREEN = {"kind": "diffuse", "albedo": (0.14, 0.45, 0.091)}
LIGHT = {"kind": "diffuse", "albedo": (0.0, 0.0, 0.0), "emission": (17.0, 12.0, 4.0)}
MIRROR = {"kind": "mirror", "albedo": (0.95, 0.95, 0.95)}
GLASS = {"kind": "dielectric", "albedo": (1.0, 1.0, 1.0), "ior": 1.5}
COPPER = {"kind": "roughconductor", "albedo": (0.95, 0.64, 0.54), "alpha": 0.2}

CAMERA = ((278.0, 273.0, -800.0), (278.0, 273.0, 0.0), (0.0, 1.0, 0.0),
          2.0 * math.degrees(math.atan(12.5 / 35.0)))

# Quads (a, b, c, d) -> triangles (a, b, c), (a, c, d), as pathbench's add_quad.
ROOM = [
    ("floor", [((552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2))], WHITE),
    ("back", [((549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2))], WHITE),
    ("right", [((0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2))], GREEN),
    ("left", [((552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0))], RED),
    ("light", [((343, 548.8, 227), (343, 548.8, 332), (213, 548.8, 332), (213, 548.8, 227))], LIGHT),
]
_C = [(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0)]
_L = ROOM[4][1][0]
CEILING = [(_C[0], _C[1], _L[1], _L[0]), (_C[1], _C[2], _L[2], _L[1]), (_C[2], _C[3], _L[3], _L[2]),
           (_C[3], _C[0], _L[0], _L[3])]
SHORT_BLOCK = [
    ((130, 165, 65), (82, 165, 225), (240, 165, 272), (290, 165, 114)),
    ((290, 0, 114), (290, 165, 114), (240, 165, 272), (240, 0, 272)),
    ((130, 0, 65), (130, 165, 65), (290, 165, 114), (290, 0, 114)),
    ((82, 0, 225), (82, 165, 225), (130, 165, 65), (130, 0, 65)),
    ((240, 0, 272), (240, 165, 272), (82, 165, 225), (82, 0, 225)),
]
TALL_BLOCK = [
    ((423, 330, 247), (265, 330, 296), (314, 330, 456), (472, 330, 406)),
    ((423, 0, 247), (423, 330, 247), (472, 330, 406), (472, 0, 406)),
    ((472, 0, 406), (472, 330, 406), (314, 330, 456), (314, 0, 456)),
    ((314, 0, 456), (314, 330, 456), (265, 330, 296), (265, 0, 296)),
    ((265, 0, 296), (265, 330, 296), (423, 330, 247), (423, 0, 247)),
]
SPHERES = [((380.0, 100.0, 360.0), 100.0, MIRROR, "mirror-sphere"), ((175.0, 100.0, 190.0), 100.0, GLASS, "glass-sphere")]
SPHERE_LEVEL = 4


def quads_mesh(quads):
    verts, faces = [], []
    for q in quads:
        base = len(verts)
        verts += [tuple(float(x) for x in p) for p in q]
        faces += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    return verts, faces


def _normalize32(v):
    v = np.asarray(v, dtype=np.float32)
    d = np.float32(v[0] * v[0]) + np.float32(v[1] * v[1])
    d = np.float32(d + np.float32(v[2] * v[2]))
    return v * (np.float32(1) / np.sqrt(d, dtype=np.float32))


def icosphere(centre, radius, level):
    """pathbench's append_icosphere (common/src/scenes/icosphere.cpp), in float32: the
    icosahedron subdivided `level` times, midpoints pushed onto the unit sphere."""
    t = np.float32((1.0 + math.sqrt(5.0)) / 2.0)
    p = [_normalize32(v) for v in [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                                    (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
            (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
            (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        mid = {}

        def get(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                mid[key] = len(p)
                p.append(_normalize32(p[key[0]] + p[key[1]]))
            return mid[key]

        nxt = []
        for a, b, c in tris:
            ab, bc, ca = get(a, b), get(b, c), get(c, a)
            nxt += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = nxt
    c = np.asarray(centre, dtype=np.float32)
    verts = [tuple(float(x) for x in c + v * np.float32(radius)) for v in p]
    return verts, tris


def parts(variant: str = ""):
    if variant not in VARIANTS:
        raise ValueError(f"cornell-box: unknown variant '{variant}' (expected one of {', '.join(VARIANTS[1:])})")
    out = [(name, *quads_mesh(quads), mat) for name, quads, mat in ROOM]
    out.append(("ceiling", *quads_mesh(CEILING), WHITE))
    short, tall = WHITE, WHITE
    if variant == "mirror":
        tall = MIRROR
    elif variant == "glass":
        short = GLASS
    elif variant == "ggx":
        tall = COPPER
    if variant == "spheres":
        for centre, radius, mat, name in SPHERES:
            out.append((name, *icosphere(centre, radius, SPHERE_LEVEL), mat))
    else:
        out.append(("short-block", *quads_mesh(SHORT_BLOCK), short))
        out.append(("tall-block", *quads_mesh(TALL_BLOCK), tall))
    return out
