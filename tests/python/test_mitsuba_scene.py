"""tools/mitsuba_scene.py: the Mitsuba 3 version of paper-cornell is the paper's scene
(../shared/paper-scene.md) and is oriented like pathbench's image. Tests that need
Mitsuba skip when it is not importable; the comparison with pathbench skips when no
pathbench binary is built."""
import math
import os
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import mitsuba_scene as ms

ROOT = Path(__file__).resolve().parents[2]


def normal(tri):
    a, b, c = (np.array(ms.VERTICES[i], dtype=float) for i in tri)
    n = np.cross(b - a, c - a)
    return n / np.linalg.norm(n)


# ---- The scene as data (no Mitsuba needed) ------------------------------------------

def test_twelve_vertices_fourteen_triangles():
    assert len(ms.VERTICES) == 12
    assert ms.triangle_count() == 14
    assert [name for name, *_ in ms.PARTS] == ["left", "back", "right", "ceiling", "floor", "front", "light"]


def test_triangles_and_materials_as_the_paper():
    parts = {name: (tris, albedo, emission) for name, tris, albedo, emission in ms.PARTS}
    assert parts["left"] == ([(0, 1, 2), (0, 2, 3)], (0.5, 0.0, 0.0), None)
    assert parts["right"] == ([(5, 7, 6), (5, 4, 7)], (0.0, 0.5, 0.0), None)
    assert parts["light"][0] == [(10, 9, 8), (11, 10, 8)]
    assert parts["light"][2] == (10.0, 10.0, 10.0)
    for name in ("back", "ceiling", "floor", "front"):
        assert parts[name][1] == (0.5, 0.5, 0.5)


def test_light_faces_down_and_front_wall_faces_out():
    for tri in dict((n, t) for n, t, *_ in ms.PARTS)["light"]:
        assert np.allclose(normal(tri), [0, -1, 0])
    for name, tris, *_ in ms.PARTS:
        for tri in tris:
            centre = np.mean([ms.VERTICES[i] for i in tri], axis=0)
            inward = np.dot(normal(tri), np.array([0, 0, 6]) - centre) > 0  # box centre (0, 0, 6)
            if name == "front":
                assert not inward, "the front wall faces out of the box (two-sidedness matters)"
            elif name != "light":
                assert inward, name


def test_camera():
    assert ms.CAMERA_ORIGIN == (0, 0, 20)
    assert ms.CAMERA_TARGET[2] < ms.CAMERA_ORIGIN[2] and ms.CAMERA_TARGET[:2] == (0, 0)
    assert ms.CAMERA_UP == (0, 1, 0)
    assert ms.FOV_DEG == pytest.approx(57.853, abs=1e-3)
    assert math.tan(math.radians(ms.FOV_DEG / 2)) == pytest.approx(10.5 / 19)
    assert ms.MAX_DEPTH == 3 and ms.WIDTH == ms.HEIGHT == 256


def test_part_meshes_keep_their_own_vertices():
    for _, tris, *_ in ms.PARTS:
        verts, faces = ms.part_mesh(tris)
        assert len(faces) == 2 and len(verts) == 4
        assert [tuple(verts[i] for i in f) for f in faces] == [tuple(ms.VERTICES[i] for i in t) for t in tris]


def test_xml_file(tmp_path):
    path = ms.write_xml(tmp_path, spp=16)
    root = ET.parse(path).getroot()
    shapes = root.findall("shape")
    assert len(shapes) == 7
    assert root.find("integrator/integer[@name='max_depth']").get("value") == "3"
    assert float(root.find("sensor/float[@name='fov']").get("value")) == pytest.approx(ms.FOV_DEG)
    assert root.find("sensor/film/rfilter").get("type") == "box"
    faces = 0
    for s in shapes:
        data = (tmp_path / f"{s.get('id')}.ply").read_bytes()
        header = data[: data.index(b"end_header")].decode()
        faces += int(header.split("element face ")[1].split()[0])
    assert faces == 14


def test_pfm_round_trip_keeps_row_zero_at_the_top(tmp_path):
    img = np.zeros((4, 3, 3), dtype=np.float32)
    img[0, :, 0] = 1  # top row red
    img[:, 0, 1] = 2  # left column green
    ms.write_pfm(tmp_path / "a.pfm", img)
    raw = (tmp_path / "a.pfm").read_bytes()
    assert raw.startswith(b"PF\n3 4\n-1.0\n")
    first_stored_row = np.frombuffer(raw[len(b"PF\n3 4\n-1.0\n"):], dtype="<f4")[:9].reshape(3, 3)
    assert first_stored_row[1, 0] == 0, "PFM stores the bottom row first"
    assert np.array_equal(ms.read_pfm(tmp_path / "a.pfm"), img)


# ---- With Mitsuba ----------------------------------------------------------------------

@pytest.fixture(scope="module")
def mi():
    mitsuba = pytest.importorskip("mitsuba", reason="mitsuba is not installed (pip install mitsuba)")
    variant = "llvm_ad_rgb" if os.path.exists(ms.LLVM_DEFAULT) or "DRJIT_LIBLLVM_PATH" in os.environ else "scalar_rgb"
    try:
        return ms.import_mitsuba(variant)
    except Exception:  # noqa: BLE001 (no LLVM after all)
        return ms.import_mitsuba("scalar_rgb")
    del mitsuba


def scalar(x):
    return float(np.ravel(np.array(x))[0])


def test_mitsuba_scene_has_14_triangles_and_one_emitter(mi):
    scene = ms.load_scene(mi, width=32, height=32, spp=4)
    shapes = scene.shapes()
    assert len(shapes) == 7
    assert sum(s.face_count() for s in shapes) == 14
    assert sum(s.vertex_count() for s in shapes) == 28
    assert len(scene.emitters()) == 1
    area = sum(scalar(s.surface_area()) for s in shapes if s.is_emitter())
    assert area == pytest.approx(60.0, rel=1e-5)


def test_mitsuba_camera(mi):
    scene = ms.load_scene(mi, width=32, height=32, spp=4)
    sensor = scene.sensors()[0]
    params = mi.traverse(sensor)
    assert scalar(params["x_fov"]) == pytest.approx(ms.FOV_DEG, rel=1e-5)  # square image: x fov = y fov
    m = np.array(params["to_world"].matrix).reshape(4, 4)
    assert np.allclose(m[:3, 3], [0, 0, 20])   # position
    assert np.allclose(m[:3, 2], [0, 0, -1])   # Mitsuba cameras look along local +z
    assert np.allclose(m[:3, 1], [0, 1, 0])    # up
    assert list(sensor.film().size()) == [32, 32]
    assert sensor.film().rfilter().radius() == pytest.approx(0.5)  # box: a sample counts in its own pixel only


def test_mitsuba_image_orientation(mi):
    """Red wall on the left, light at the top, as pathbench's image."""
    scene = ms.load_scene(mi, width=64, height=64, spp=16)
    img = ms.render(mi, scene, 16, seed=1)
    assert img.shape == (64, 64, 3)
    left, right = img[:, :8].mean(axis=(0, 1)), img[:, -8:].mean(axis=(0, 1))
    assert left[0] > 5 * left[1], "red wall on the left"
    assert right[1] > 5 * right[0], "green wall on the right"
    assert img[:16].max() == pytest.approx(10.0, rel=1e-6), "the light is in the top quarter"
    assert img[-16:].max() < 10.0


def find_pathbench():
    for p in (os.environ.get("PATHBENCH_BIN"), ROOT / "build" / "bin" / "pathbench",
              ROOT / "build-stats" / "bin" / "pathbench", shutil.which("pathbench")):
        if p and Path(p).is_file() and os.access(p, os.X_OK):
            return Path(p)
    return None


def test_mitsuba_matches_pathbench_orientation_and_mean(mi, tmp_path):
    pathbench = find_pathbench()
    if pathbench is None:
        pytest.skip("no pathbench binary (scripts/build.sh, or set PATHBENCH_BIN)")
    size, spp = 64, 64
    out = tmp_path / "pb.pfm"
    subprocess.run([str(pathbench), "render", "--scene", "paper-cornell", "--width", str(size), "--height", str(size),
                    "--spp", str(spp), "--bounces", "2", "--sampling", "nee", "--out", str(out), "--quiet"], check=True)
    ours = ms.read_pfm(out)
    theirs = ms.render(mi, ms.load_scene(mi, width=size, height=size, spp=spp), spp, seed=3)
    diff = lambda a, b: float(np.abs(a - b).mean())  # noqa: E731
    as_is = diff(ours, theirs)
    assert as_is < 0.5 * diff(ours[:, ::-1], theirs), "mirrored left-right"
    assert as_is < 0.5 * diff(ours[::-1], theirs), "mirrored top-bottom"
    assert ours.reshape(-1, 3).mean(axis=0) == pytest.approx(theirs.reshape(-1, 3).mean(axis=0), rel=0.01)


def test_xml_file_loads_in_mitsuba(mi, tmp_path):
    scene = mi.load_file(str(ms.write_xml(tmp_path, spp=4, width=16, height=16)))
    assert sum(s.face_count() for s in scene.shapes()) == 14
    assert len(scene.emitters()) == 1
    img = np.array(mi.render(scene, spp=4))[:, :, :3]
    assert img.shape == (16, 16, 3) and img.max() == pytest.approx(10.0, rel=1e-6)
