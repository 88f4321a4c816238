#!/usr/bin/env python3
"""Writes a many-instance scene: an ico sphere (OBJ) placed N x N x N times in a grid, each
copy turned about its own random axis, scaled unevenly (and mirrored now and then, which
flips the flat copy's winding), over a floor under an area light.

    make_instance_grid.py OUT_DIR [--n 5] [--subdiv 2] [--seed 1]

writes OUT_DIR/ico<subdiv>.obj and OUT_DIR/grid-<n^3>.json. Deterministic for a seed.
tests/data/scenes/instances/ holds the 5^3 = 125 copy scene of the instancing identity tests
(tests/unit/test_instancing.cpp); --n 10 --subdiv 3 is the 1000-copy scene whose BVH sizes
docs/notes/cpu-log.md and docs/notes/gpu-log.md give.
"""
import argparse
import json
import math
import os
import random


def icosphere(subdiv):
    t = (1 + 5 ** 0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdiv):
        mid = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = [(x + y) / 2 for x, y in zip(verts[a], verts[b])]
                n = math.sqrt(sum(x * x for x in m))
                verts.append(tuple(x / n for x in m))
                mid[key] = len(verts) - 1
            return mid[key]

        faces = [f for a, b, c in faces for f in (
            (a, middle(a, b), middle(c, a)), (b, middle(b, c), middle(a, b)), (c, middle(c, a), middle(b, c)),
            (middle(a, b), middle(b, c), middle(c, a)))]
    return verts, faces


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    ap.add_argument("--n", type=int, default=5, help="copies per axis (N^3 in all)")
    ap.add_argument("--subdiv", type=int, default=2, help="ico sphere subdivisions (20 * 4^s triangles)")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    os.makedirs(a.out_dir, exist_ok=True)
    obj = f"ico{a.subdiv}.obj"
    verts, faces = icosphere(a.subdiv)
    with open(os.path.join(a.out_dir, obj), "w") as f:
        f.write(f"# ico sphere, {a.subdiv} subdivisions (make_instance_grid.py)\n")
        f.writelines(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in verts)
        f.writelines(f"f {i + 1} {j + 1} {k + 1}\n" for i, j, k in faces)
    spacing = 2.5
    half = (a.n - 1) * spacing / 2
    instances = []
    for i in range(a.n):
        for j in range(a.n):
            for k in range(a.n):
                axis = [rng.uniform(-1, 1) for _ in range(3)]
                scale = [rng.uniform(0.6, 1.1) * (-1 if rng.random() < 0.1 else 1) for _ in range(3)]
                instances.append({"scale": [round(s, 4) for s in scale],
                                  "rotate": {"axis": [round(x, 4) for x in axis], "angle": round(rng.uniform(0, 360), 3)},
                                  "translate": [i * spacing - half, j * spacing + 1.2, k * spacing - half]})
    size = half + 4
    top = 2 * half + 5
    lt = max(2.0, 0.7 * half)
    scene = {
        "description": f"{a.n ** 3} rotated, unevenly scaled copies of {obj} (make_instance_grid.py --n {a.n} "
                       f"--subdiv {a.subdiv} --seed {a.seed})",
        "camera": {"position": [half * 0.6, half + 2, 2.6 * half + 8], "look_at": [0, half + 1, 0], "up": [0, 1, 0],
                   "fov_y_deg": 45},
        "materials": {"ico": {"albedo": [0.6, 0.5, 0.3]}, "floor": {"albedo": [0.7, 0.7, 0.7]},
                      "light": {"emission": [10, 10, 10]}},
        "meshes": [{"file": obj, "material": "ico", "instances": instances}],
        "triangles": [
            {"material": "floor", "vertices": [[-size, 0, -size], [-size, 0, size], [size, 0, size], [size, 0, -size]],
             "indices": [[0, 1, 2], [0, 2, 3]]},
            {"material": "light", "vertices": [[-lt, top, -lt], [lt, top, -lt], [lt, top, lt], [-lt, top, lt]],
             "indices": [[0, 1, 2], [0, 2, 3]]}],
    }
    with open(os.path.join(a.out_dir, f"grid-{a.n ** 3}.json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
