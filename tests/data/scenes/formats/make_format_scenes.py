#!/usr/bin/env python3
"""Writes the format test scenes beside this file (committed; rerun after a change):
one scene as JSON (instanced.json, and flattened.json without instancing), glTF (instanced.gltf, .glb), Mitsuba 3 XML
(instanced.xml), and cube.obj as ASCII and binary PLY. test_scene_formats.cpp checks
that each loads to the same triangles as its JSON or OBJ twin."""
import json, math, struct, sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[3] / "tools"))
import gltf_buffers  # noqa: E402
V = [(-0.5, -0.5, -0.5), (0.5, -0.5, -0.5), (0.5, 0.5, -0.5), (-0.5, 0.5, -0.5),
     (-0.5, -0.5, 0.5), (0.5, -0.5, 0.5), (0.5, 0.5, 0.5), (-0.5, 0.5, 0.5)]
QUADS = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]  # cube.obj, 0-based

# cube.obj as triangles (the quads fanned from their first corner), so that every twin
# has the same triangles whichever diagonal a reader would split a quad along.
TRIS = [t for q in QUADS for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]
(HERE / "cube.obj").write_text("# scenes/cube.obj with its quads as triangles (make_format_scenes.py)\n" +
                               "".join(f"v {x} {y} {z}\n" for x, y, z in V) +
                               "".join("f %d %d %d\n" % tuple(i + 1 for i in t) for t in TRIS))

def ply(fmt):
    """ASCII: the quads (the reader fans them); binary: the triangles."""
    head = ["ply", f"format {fmt} 1.0", "comment cube.obj as PLY", f"element vertex {len(V)}",
            "property float x", "property float y", "property float z", f"element face {len(QUADS) if fmt == 'ascii' else len(TRIS)}",
            "property list uchar int vertex_indices", "end_header"]
    out = ("\n".join(head) + "\n").encode()
    if fmt == "ascii":
        body = "".join(f"{x} {y} {z}\n" for x, y, z in V) + "".join("4 " + " ".join(map(str, q)) + "\n" for q in QUADS)
        return out + body.encode()
    e = "<" if fmt == "binary_little_endian" else ">"
    for p in V:
        out += struct.pack(e + "3f", *p)
    for t in TRIS:
        out += struct.pack(e + "B3i", 3, *t)
    return out

for name, fmt in [("cube-ascii.ply", "ascii"), ("cube-le.ply", "binary_little_endian"), ("cube-be.ply", "binary_big_endian")]:
    (HERE / name).write_bytes(ply(fmt))

# The scene: a cube placed twice (a rotated copy and one by a 3x4 matrix), a floor and a light.
ROT = {"axis": [0, 1, 0], "angle": 30}
MOVE = [-1, 0.5, 0]
MATRIX = [[0.8, 0, 0, 1], [0, 2, 0, 1], [0, 0, 0.8, -0.5]]
FLOOR = [[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]]
LIGHT = [[-0.5, 3.5, -0.5], [0.5, 3.5, -0.5], [0.5, 3.5, 0.5], [-0.5, 3.5, 0.5]]
CAMERA = {"position": [0, 1, 6], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov_y_deg": 40}
scene = {
    "description": "Twin of instanced.gltf and instanced.xml (make_format_scenes.py).",
    "camera": CAMERA,
    "materials": {"blue": {"albedo": [0.1, 0.2, 0.6]}, "white": {"albedo": [0.75, 0.75, 0.75]},
                  "light": {"emission": [6, 6, 6]}},
    "meshes": [{"file": "cube.obj", "material": "blue", "instances": [{"rotate": ROT, "translate": MOVE}, {"matrix": MATRIX}]}],
    "triangles": [{"material": "white", "vertices": FLOOR, "indices": [[0, 1, 2], [0, 2, 3]]},
                  {"material": "light", "vertices": LIGHT, "indices": [[0, 1, 2], [0, 2, 3]]}],
}
(HERE / "instanced.json").write_text(json.dumps(scene, indent=1) + "\n")
# The same scene without instancing: the mesh listed once per placement.
flat = dict(scene, description="instanced.json flattened by hand (make_format_scenes.py).")
flat["meshes"] = [{"file": "cube.obj", "material": "blue", "transform": t} for t in scene["meshes"][0]["instances"]]
(HERE / "flattened.json").write_text(json.dumps(flat, indent=1) + "\n")

# glTF: one buffer (cube, floor, light positions and indices), embedded as base64.
buf = gltf_buffers.Buffer()
half = math.radians(ROT["angle"]) / 2
gltf = {
    "asset": {"version": "2.0", "generator": "pathbench make_format_scenes.py"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
    "nodes": [
        {"mesh": 0, "rotation": [0, math.sin(half), 0, math.cos(half)], "translation": MOVE},
        {"mesh": 0, "matrix": [MATRIX[r][c] if r < 3 else (1.0 if c == 3 else 0.0) for c in range(4) for r in range(4)]},
        {"mesh": 1}, {"mesh": 2},
        {"camera": 0, "translation": CAMERA["position"]},
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": math.radians(CAMERA["fov_y_deg"]), "znear": 0.01}}],
    "materials": [
        {"name": "blue", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.6, 1], "metallicFactor": 0}},
        {"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.75, 0.75, 0.75, 1], "metallicFactor": 0}},
        {"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0},
         "emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 6}}},
    ],
    "extensionsUsed": ["KHR_materials_emissive_strength"],
    "meshes": [buf.mesh(V, TRIS, 0), buf.mesh(FLOOR, [(0, 1, 2), (0, 2, 3)], 1), buf.mesh(LIGHT, [(0, 1, 2), (0, 2, 3)], 2)],
}
gltf = buf.finish(gltf)
blob = buf.blob
(HERE / "instanced.gltf").write_text(json.dumps(gltf, indent=1) + "\n")
# The same as a .glb: the JSON chunk, then the buffer as the BIN chunk.
glb_json = dict(gltf, buffers=[{"byteLength": len(blob)}])
chunk = json.dumps(glb_json).encode()
chunk += b" " * (-len(chunk) % 4)
bin_chunk = blob + b"\0" * (-len(blob) % 4)
body = struct.pack("<II", len(chunk), 0x4E4F534A) + chunk + struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
(HERE / "instanced.glb").write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)

m = " ".join(str(MATRIX[r][c]) for r in range(3) for c in range(4)) + " 0 0 0 1"
(HERE / "instanced.xml").write_text(f"""<!-- Twin of instanced.json (make_format_scenes.py): Mitsuba 3 renders it as it is. -->
<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="{CAMERA['fov_y_deg']}"/>
    <string name="fov_axis" value="y"/>
    <transform name="to_world"><lookat origin="0, 1, 6" target="0, 1, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm">
      <integer name="width" value="64"/><integer name="height" value="48"/>
      <rfilter type="box"/>
    </film>
  </sensor>
  <bsdf type="twosided" id="blue"><bsdf type="diffuse"><rgb name="reflectance" value="0.1, 0.2, 0.6"/></bsdf></bsdf>
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.75"/></bsdf></bsdf>
  <shape type="shapegroup" id="cube">
    <shape type="obj"><string name="filename" value="cube.obj"/><ref id="blue"/></shape>
  </shape>
  <shape type="instance"><ref id="cube"/>
    <transform name="to_world"><rotate y="1" angle="{ROT['angle']}"/><translate x="{MOVE[0]}" y="{MOVE[1]}" z="{MOVE[2]}"/></transform>
  </shape>
  <shape type="instance"><ref id="cube"/><transform name="to_world"><matrix value="{m}"/></transform></shape>
  <shape type="rectangle">
    <transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/></transform>
    <ref id="white"/>
  </shape>
  <shape type="rectangle">
    <transform name="to_world"><rotate x="1" angle="90"/><scale value="0.5"/><translate y="3.5"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
    <emitter type="area"><rgb name="radiance" value="6"/></emitter>
  </shape>
</scene>
""")
