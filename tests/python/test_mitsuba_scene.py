"""tools/mitsuba_scene.py: paper-cornell as pathbench exports it to Mitsuba 3
(pathbench.export_mitsuba) is the paper's scene (../shared/paper-scene.md) and is
oriented like pathbench's image. Tests that need Mitsuba skip when it is not importable;
the comparison with pathbench skips when no pathbench binary is built."""
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


# ---- The export (pathbench.export_mitsuba; no Mitsuba needed) -----------------------

def ply_faces(path):
    data = path.read_bytes()
    header = data[: data.index(b"end_header")].decode()
    return int(header.split("element face ")[1].split()[0])


def test_xml_file(tmp_path):
    """paper-cornell as pathbench exports it: one PLY per material (red, white, green, light),
    14 triangles, the paper's camera (../shared/paper-scene.md), max_depth 3 for two bounces."""
    path = ms.write_xml(tmp_path, width=32, height=16)
    root = ET.parse(path).getroot()
    shapes = root.findall("shape")
    assert len(shapes) == 4
    assert sum(ply_faces(tmp_path / s.find("string[@name='filename']").get("value")) for s in shapes) == 14
    assert root.find("integrator/integer[@name='max_depth']").get("value") == "3"
    assert int(root.find("integrator/integer[@name='rr_depth']").get("value")) > 3, "no Russian roulette"
    fov = float(root.find("sensor/float[@name='fov']").get("value"))
    assert math.tan(math.radians(fov / 2)) == pytest.approx(10.5 / 19, rel=1e-6)
    assert root.find("sensor/string[@name='fov_axis']").get("value") == "y"
    look = root.find("sensor/transform/lookat")
    assert [float(x) for x in look.get("origin").split(",")] == [0, 0, 20]
    assert [float(x) for x in look.get("up").split(",")] == [0, 1, 0]
    assert root.find("sensor/film/integer[@name='width']").get("value") == "32"
    assert root.find("sensor/film/integer[@name='height']").get("value") == "16"
    assert root.find("sensor/film/rfilter").get("type") == "box"
    emitters = [s for s in shapes if s.find("emitter") is not None]
    assert len(emitters) == 1
    assert emitters[0].find("emitter/rgb").get("value").replace(" ", "") == "10,10,10"


def test_bounces_and_converged(tmp_path):
    depth = lambda p: ET.parse(p).getroot().find("integrator/integer[@name='max_depth']").get("value")  # noqa: E731
    assert depth(ms.write_xml(tmp_path / "a", max_depth=6)) == "6"
    assert depth(ms.write_xml(tmp_path / "b", max_depth=-1)) == "-1"


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
    assert len(shapes) == 4  # one mesh per material
    assert sum(s.face_count() for s in shapes) == 14
    assert len(scene.emitters()) == 1
    area = sum(scalar(s.surface_area()) for s in shapes if s.is_emitter())
    assert area == pytest.approx(60.0, rel=1e-5)


def test_mitsuba_camera(mi):
    scene = ms.load_scene(mi, width=32, height=32, spp=4)
    sensor = scene.sensors()[0]
    params = mi.traverse(sensor)
    fov = 2.0 * math.degrees(math.atan(10.5 / 19.0))  # ../shared/paper-scene.md
    assert scalar(params["x_fov"]) == pytest.approx(fov, rel=1e-5)  # square image: x fov = y fov
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
    scene = mi.load_file(str(ms.write_xml(tmp_path, width=16, height=16)))
    assert sum(s.face_count() for s in scene.shapes()) == 14
    assert len(scene.emitters()) == 1
    img = np.array(mi.render(scene, spp=4))[:, :, :3]
    assert img.shape == (16, 16, 3) and img.max() == pytest.approx(10.0, rel=1e-6)
