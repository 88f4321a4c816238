#!/usr/bin/env python3
"""Writes the suite's scene files (scenes/suite/*.json) deterministically; the committed
files are its output (tests/python/test_suite_workloads.py checks they match).

    python3 scenes/suite/make_suite_scenes.py [OUT_DIR]     (default: this folder)

Meshes are named "data:meshes/FILE.off": pathbench's data folder, where
scripts/install-suite-data.sh puts the scanned meshes of Debian's libcgal-demo.
The instanced fields use Python's random.Random(seed).random() only (stable across
Python versions), rounded to 4 decimals.
"""
from __future__ import annotations

import json
import math
import random
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

# ---- the paper's box (../paper-cornell.json, ../../../shared/paper-scene.md) ----
PAPER_CAMERA = {"position": [0, 0, 20], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 57.8528481}
PAPER_MATERIALS = {
    "red": {"albedo": [0.5, 0, 0]},
    "white": {"albedo": [0.5, 0.5, 0.5]},
    "green": {"albedo": [0, 0.5, 0]},
    "light": {"albedo": [0, 0, 0], "emission": [10, 10, 10]},
}
PAPER_TRIANGLES = [
    {"material": "red", "vertices": [[-10, -10, 22], [-10, -10, -10], [-10, 10, -10], [-10, 10, 22]],
     "indices": [[0, 1, 2], [0, 2, 3]]},
    {"material": "white", "vertices": [[-10, -10, -10], [10, -10, -10], [10, 10, -10], [-10, 10, -10]],
     "indices": [[0, 1, 2], [0, 2, 3]]},
    {"material": "green", "vertices": [[10, -10, -10], [10, 10, 22], [10, 10, -10], [10, -10, 22]],
     "indices": [[0, 1, 2], [0, 3, 1]]},
    {"material": "white",
     "vertices": [[-10, -10, 22], [-10, -10, -10], [-10, 10, -10], [-10, 10, 22],
                  [10, -10, 22], [10, -10, -10], [10, 10, -10], [10, 10, 22]],
     "indices": [[2, 7, 3], [2, 6, 7], [0, 5, 1], [0, 4, 5], [0, 7, 3], [0, 4, 7]]},
    {"material": "light", "vertices": [[-5, 9.9, -8], [-5, 9.9, -2], [5, 9.9, -2], [5, 9.9, -8]],
     "indices": [[2, 1, 0], [3, 2, 0]]},
]

# Placements that stand each scanned mesh on y = 0, centred on x and z, about one unit
# tall (bounds measured from the libcgal-demo 5.5.1 files; +y is up in all four).
#   file: (centre x, lowest y, centre z, height)
MESHES = {
    "bunny00.off": (0.00013, -0.493434, -0.000202, 0.987201),
    "armadillo.off": (0.0086, -54.2018, 0.0072, 151.3094),
    "ChineseDragon-10kv.off": (-3.63435, -52.6971168518, -981.971588, 112.8882027),
    "refined_elephant.off": (-0.000193, -0.499404484375, -0.000275, 0.996876),
}


def place(name: str, height: float, at, yaw: float = 0.0) -> list:
    """Transforms (applied first to last) putting mesh `name` at `at` on its base, `height`
    tall, turned `yaw` degrees about +y."""
    cx, y0, cz, h = MESHES[name]
    s = height / h
    steps = [{"translate": [-cx, -y0, -cz]}, {"scale": round(s, 9)}]
    if yaw:
        steps.append({"rotate": {"axis": [0, 1, 0], "angle": yaw}})
    steps.append({"translate": list(at)})
    return steps


def mesh(name: str, material: str, transform, **extra) -> dict:
    return {"file": f"data:meshes/{name}", "material": material, **extra, "transform": transform}


def paper_box(description: str, materials: dict, meshes: list) -> dict:
    return {"description": description, "camera": PAPER_CAMERA, "materials": {**PAPER_MATERIALS, **materials},
            "meshes": meshes, "triangles": PAPER_TRIANGLES}


FLOOR = -10  # the paper box's floor

GOLD = {"kind": "roughconductor", "albedo": [0.95, 0.75, 0.35], "alpha": 0.15}
COPPER = {"kind": "roughconductor", "albedo": [0.95, 0.64, 0.54], "alpha": 0.2}
GLASS = {"kind": "dielectric", "ior": 1.5}
MIRROR = {"kind": "mirror", "albedo": [0.95, 0.95, 0.95]}


def bunny_armadillo() -> dict:
    return paper_box(
        "Suite v1 'bunny-armadillo': the paper's box with the Stanford bunny (diffuse, 75k faces) and the armadillo "
        "(GGX rough gold, 52k faces), both from Debian's libcgal-demo.",
        {"clay": {"albedo": [0.7, 0.7, 0.7]}, "gold": GOLD},
        [mesh("bunny00.off", "clay", place("bunny00.off", 8.0, [-4.6, FLOOR, -3.0], yaw=20)),
         mesh("armadillo.off", "gold", place("armadillo.off", 11.0, [4.6, FLOOR, -3.5], yaw=155))])


def glass_dragon() -> dict:
    return paper_box(
        "Suite v1 'glass-dragon': the paper's box with a glass Chinese dragon (20k faces) in front of a rough-copper "
        "elephant (89k faces, GGX) and a diffuse bunny, from Debian's libcgal-demo.",
        {"glass": GLASS, "copper": COPPER, "clay": {"albedo": [0.7, 0.7, 0.7]}},
        [mesh("ChineseDragon-10kv.off", "glass", place("ChineseDragon-10kv.off", 10.0, [0.5, FLOOR, 1.0], yaw=-35)),
         mesh("refined_elephant.off", "copper", place("refined_elephant.off", 9.0, [-4.5, FLOOR, -6.0], yaw=30)),
         mesh("bunny00.off", "clay", place("bunny00.off", 5.0, [5.5, FLOOR, -6.5], yaw=-10))])


def large_mesh(levels: int) -> dict:
    n = 52000 * 4 ** levels
    return paper_box(
        f"Suite v1 'large-mesh': the armadillo (52k faces, Debian libcgal-demo) refined by {levels} levels of Loop "
        f"subdivision at load time ({n:,} triangles), diffuse, in the paper's box.",
        {"clay": {"albedo": [0.7, 0.7, 0.7]}},
        [mesh("armadillo.off", "clay", place("armadillo.off", 14.0, [0.0, FLOOR, -2.0], yaw=160), subdivide=levels)])


def cornell_materials() -> dict:
    """The Cornell box (scene_io/src/scenes/cornell_box.cpp, millimetres) with a rough-copper
    (GGX) tall block, a glass short block and a mirror cube (../cube.obj) turned 45 degrees
    at the front left, showing the red and green walls."""
    def quad(a, b, c, d, m):
        return {"material": m, "vertices": [a, b, c, d], "indices": [[0, 1, 2], [0, 2, 3]]}
    L = [[343, 548.8, 227], [343, 548.8, 332], [213, 548.8, 332], [213, 548.8, 227]]
    C = [[556, 548.8, 0], [556, 548.8, 559.2], [0, 548.8, 559.2], [0, 548.8, 0]]
    tris = [
        quad([552.8, 0, 0], [0, 0, 0], [0, 0, 559.2], [549.6, 0, 559.2], "white"),
        quad([549.6, 0, 559.2], [0, 0, 559.2], [0, 548.8, 559.2], [556, 548.8, 559.2], "white"),
        quad([0, 0, 559.2], [0, 0, 0], [0, 548.8, 0], [0, 548.8, 559.2], "green"),
        quad([552.8, 0, 0], [549.6, 0, 559.2], [556, 548.8, 559.2], [556, 548.8, 0], "red"),
        quad(L[0], L[1], L[2], L[3], "light"),
        quad(C[0], C[1], L[1], L[0], "white"), quad(C[1], C[2], L[2], L[1], "white"),
        quad(C[2], C[3], L[3], L[2], "white"), quad(C[3], C[0], L[0], L[3], "white"),
        # short block (glass): top, four sides
        quad([130, 165, 65], [82, 165, 225], [240, 165, 272], [290, 165, 114], "glass"),
        quad([290, 0, 114], [290, 165, 114], [240, 165, 272], [240, 0, 272], "glass"),
        quad([130, 0, 65], [130, 165, 65], [290, 165, 114], [290, 0, 114], "glass"),
        quad([82, 0, 225], [82, 165, 225], [130, 165, 65], [130, 0, 65], "glass"),
        quad([240, 0, 272], [240, 165, 272], [82, 165, 225], [82, 0, 225], "glass"),
        # tall block (rough copper)
        quad([423, 330, 247], [265, 330, 296], [314, 330, 456], [472, 330, 406], "copper"),
        quad([423, 0, 247], [423, 330, 247], [472, 330, 406], [472, 0, 406], "copper"),
        quad([472, 0, 406], [472, 330, 406], [314, 330, 456], [314, 0, 456], "copper"),
        quad([314, 0, 456], [314, 330, 456], [265, 330, 296], [265, 0, 296], "copper"),
        quad([265, 0, 296], [265, 330, 296], [423, 330, 247], [423, 0, 247], "copper"),
    ]
    fov = 2 * math.degrees(math.atan(12.5 / 35))
    return {
        "description": "Suite v1 'cornell-materials': the Cornell box (cornell-box, Cornell University's published "
                       "data) with a rough-copper (GGX) tall block, a glass short block and a mirror cube in front.",
        "camera": {"position": [278, 273, -800], "look_at": [278, 273, 0], "up": [0, 1, 0],
                   "fov_y_deg": round(fov, 7)},
        "materials": {"white": {"albedo": [0.75, 0.75, 0.75]}, "red": {"albedo": [0.63, 0.065, 0.05]},
                      "green": {"albedo": [0.14, 0.45, 0.091]}, "light": {"emission": [17, 12, 4]},
                      "mirror": MIRROR, "glass": GLASS, "copper": COPPER},
        "meshes": [{"file": "../cube.obj", "material": "mirror",
                    "transform": {"scale": 100, "rotate": {"axis": [0, 1, 0], "angle": 45},
                                  "translate": [420, 50, 120]}}],
        "triangles": tris,
    }


def instanced_field(side: int, seed: int = 2026) -> dict:
    """side x side cells, each a dragon or (every fifth, by a draw) an armadillo, turned,
    scaled 0.7-1.3 and jittered; a floor and a large light above."""
    rng = random.Random(seed)
    spacing = 1.5
    half = (side - 1) * spacing / 2
    dragons, armadillos = [], []
    for i in range(side):
        for j in range(side):
            u, yaw, s, jx, jz = (rng.random() for _ in range(5))
            name = "armadillo.off" if u < 0.2 else "ChineseDragon-10kv.off"
            h = round((0.7 + 0.6 * s) * 1.1, 4)
            at = [round(-half + i * spacing + (jx - 0.5) * 0.4, 4), 0, round(-half + j * spacing + (jz - 0.5) * 0.4, 4)]
            (armadillos if u < 0.2 else dragons).append(place(name, h, at, yaw=round(360 * yaw, 4)))
    extent = half + 3
    meshes = []
    if dragons:
        meshes.append({"file": "data:meshes/ChineseDragon-10kv.off", "material": "jade", "instances": dragons})
    if armadillos:
        meshes.append({"file": "data:meshes/armadillo.off", "material": "gold", "instances": armadillos})
    dist = max(6.0, 0.9 * half)
    return {
        "description": f"Suite v1 'instanced': a field of {side}x{side} scanned meshes from Debian's libcgal-demo, "
                       f"{len(dragons)} Chinese dragons (19,994 faces each, diffuse) and {len(armadillos)} armadillos "
                       "(52,000 faces each, GGX gold), each turned, scaled and jittered (make_suite_scenes.py, seed "
                       f"{seed}), on a floor under an area light. Render with --instancing on.",
        "camera": {"position": [0, round(0.55 * dist, 3), round(dist + half * 0.5, 3)], "look_at": [0, 0, round(-0.2 * half, 3)],
                   "up": [0, 1, 0], "fov_y_deg": 50},
        "materials": {"floor": {"albedo": [0.6, 0.6, 0.6]}, "jade": {"albedo": [0.3, 0.6, 0.4]}, "gold": GOLD,
                      "light": {"emission": [3, 3, 3]}},
        "meshes": meshes,
        "triangles": [
            {"material": "floor", "vertices": [[-extent, 0, -extent], [-extent, 0, extent], [extent, 0, extent],
                                               [extent, 0, -extent]], "indices": [[0, 1, 2], [0, 2, 3]]},
            {"material": "light", "vertices": [[-extent, 4 + half, -extent], [extent, 4 + half, -extent],
                                               [extent, 4 + half, extent], [-extent, 4 + half, extent]],
             "indices": [[0, 1, 2], [0, 2, 3]]},
        ],
    }


SCENES = {
    "cornell-materials.json": cornell_materials,
    "bunny-armadillo.json": bunny_armadillo,
    "glass-dragon.json": glass_dragon,
    "large-mesh.json": lambda: large_mesh(4),
    "large-mesh-quick.json": lambda: large_mesh(1),
    "instanced.json": lambda: instanced_field(68),
    "instanced-quick.json": lambda: instanced_field(4),
}


def dump(scene: dict) -> str:
    """Indented JSON, but each transform, vertex list or instance on one compact line."""
    def compact(v):
        return json.dumps(v, separators=(", ", ": "))

    def go(v, ind):
        pad = " " * ind
        if isinstance(v, dict) and not ("translate" in v or "rotate" in v or "scale" in v or "albedo" in v
                                        or "emission" in v or "position" in v):
            items = [f'{pad} {json.dumps(k)}: {go(x, ind + 1).lstrip()}' for k, x in v.items()]
            return pad + "{\n" + ",\n".join(items) + "\n" + pad + "}"
        is_transform = isinstance(v, list) and v and all(isinstance(x, dict) and x.keys() <= {"translate", "rotate", "scale"} for x in v)
        if not is_transform and isinstance(v, list) and v and isinstance(v[0], (dict, list)) and not (
                isinstance(v[0], list) and v[0] and isinstance(v[0][0], (int, float))):
            return pad + "[\n" + ",\n".join(go(x, ind + 1) for x in v) + "\n" + pad + "]"
        return pad + compact(v)
    return go(scene, 0) + "\n"


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    out = Path(argv[0]) if argv else HERE
    out.mkdir(parents=True, exist_ok=True)
    for name, make in SCENES.items():
        (out / name).write_text(dump(make()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
