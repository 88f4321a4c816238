#!/usr/bin/env python3
"""Writes pyramids.gltf beside this file (committed; rerun after a change): a glTF 2.0
scene made by the project, with one pyramid mesh placed by three nodes (TRS and a
matrix), a metallic and a diffuse material, an emissive quad light, a ground plane
under a parent node, and a perspective camera."""
import json, math, sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import gltf_buffers  # noqa: E402

buf = gltf_buffers.Buffer()

PYRAMID = [(-0.5, 0, -0.5), (0.5, 0, -0.5), (0.5, 0, 0.5), (-0.5, 0, 0.5), (0, 0.9, 0)]
PYRAMID_FACES = [(0, 1, 2), (0, 2, 3), (0, 4, 1), (1, 4, 2), (2, 4, 3), (3, 4, 0)]  # outward
QUAD = [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)]  # facing +y
QUAD_DOWN = [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)]  # facing -y
def quat_y(deg):
    h = math.radians(deg) / 2
    return [0, math.sin(h), 0, math.cos(h)]
gltf = {
    "asset": {"version": "2.0", "generator": "pathbench scenes/examples/make_gltf_example.py"},
    "scene": 0,
    "scenes": [{"name": "pyramids", "nodes": [0, 1, 2, 3, 5, 6]}],
    "nodes": [
        {"name": "metal pyramid", "mesh": 0, "translation": [-1.2, 0, 0], "rotation": quat_y(20)},
        {"name": "clay pyramid", "mesh": 1, "translation": [1.2, 0, -0.3], "rotation": quat_y(-35), "scale": [1, 1.4, 1]},
        {"name": "small pyramid", "mesh": 1, "matrix": [0.6, 0, 0, 0, 0, 0.6, 0, 0, 0, 0, 0.6, 0, 0, 0, 0.9, 1]},
        {"name": "ground parent", "translation": [0, -0.001, 0], "children": [4]},
        {"name": "ground", "mesh": 2, "scale": [4, 1, 4]},
        {"name": "light", "mesh": 3, "translation": [0, 3, 0.5], "scale": [0.6, 1, 0.6]},
        {"name": "camera", "camera": 0, "translation": [0, 1.6, 4.5], "rotation": [-0.1305262, 0, 0, 0.9914449]},
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": math.radians(40), "znear": 0.01}}],
    "materials": [
        {"name": "brushed-gold", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.75, 0.35, 1], "metallicFactor": 1,
                                                          "roughnessFactor": 0.35}},
        {"name": "clay", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.35, 0.25, 1], "metallicFactor": 0}},
        {"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1], "metallicFactor": 0}},
        {"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0},
         "emissiveFactor": [1, 0.95, 0.9], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12}}},
    ],
    "extensionsUsed": ["KHR_materials_emissive_strength"],
    "meshes": [buf.mesh(PYRAMID, PYRAMID_FACES, 0, "pyramid-gold"), buf.mesh(PYRAMID, PYRAMID_FACES, 1, "pyramid-clay"),
               buf.mesh(QUAD, [(0, 1, 2), (0, 2, 3)], 2, "ground"), buf.mesh(QUAD_DOWN, [(0, 1, 2), (0, 2, 3)], 3, "light")],
}
gltf = buf.finish(gltf)
(Path(__file__).resolve().parent / "pyramids.gltf").write_text(json.dumps(gltf, indent=1) + "\n")
