"""pathbench's cornell-box variants as Mitsuba 3 scenes (pathbench.export_mitsuba, through
tools/mitsuba_scene.py): each material exported as the Mitsuba plugin pathbench's BSDF of
that kind is defined as (scene_io/src/mitsuba_export.cpp, the one definition of that
mapping). The XML tests need no Mitsuba; the rest skip without it."""
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import mitsuba_scene as ms

VARIANTS = ["", "mirror", "glass", "spheres", "ggx"]


def bsdfs(tmp_path, variant):
    """The outermost BSDF plugin of every shape, with the inner one where it is two-sided."""
    root = ET.parse(ms.write_xml(tmp_path, "cornell-box" + (":" + variant if variant else ""), 16, 16, 5)).getroot()
    out = []
    for shape in root.findall("shape"):
        b = shape.find("bsdf")
        inner = b.find("bsdf") if b.get("type") == "twosided" else None
        out.append((b, inner, shape.find("emitter")))
    return out


def test_room_as_pathbench(tmp_path):
    shapes = bsdfs(tmp_path, "")
    emitters = [e for *_, e in shapes if e is not None]
    assert len(emitters) == 1 and emitters[0].find("rgb").get("value").replace(" ", "") == "17,12,4"
    assert {(b.get("type"), i.get("type")) for b, i, _ in shapes} == {("twosided", "diffuse")}


@pytest.mark.parametrize("variant, plugins", [
    ("mirror", {"diffuse", "conductor"}), ("glass", {"diffuse", "dielectric"}),
    ("spheres", {"diffuse", "conductor", "dielectric"}), ("ggx", {"diffuse", "roughconductor"})])
def test_variants_use_their_plugins(tmp_path, variant, plugins):
    assert {(i if i is not None else b).get("type") for b, i, _ in bsdfs(tmp_path, variant)} == plugins


def test_material_mapping(tmp_path):
    """The plugin (and its parameters) each pathbench BSDF is defined as."""
    found = {}
    for variant in ("spheres", "ggx"):
        for b, inner, _ in bsdfs(tmp_path / variant, variant):
            found[(inner if inner is not None else b).get("type")] = (b, inner)
    b, mirror = found["conductor"]
    assert b.get("type") == "twosided" and mirror.find("string[@name='material']").get("value") == "none"
    glass, _ = found["dielectric"]
    assert float(glass.find("float[@name='int_ior']").get("value")) == 1.5
    assert float(glass.find("float[@name='ext_ior']").get("value")) == 1.0
    _, rough = found["roughconductor"]
    assert rough.find("string[@name='distribution']").get("value") == "ggx"
    assert float(rough.find("float[@name='alpha']").get("value")) == pytest.approx(0.2)
    assert rough.find("string[@name='material']").get("value") == "none"


@pytest.fixture(scope="module")
def mi():
    pytest.importorskip("mitsuba", reason="mitsuba is not installed")
    try:
        return ms.import_mitsuba("llvm_ad_rgb")
    except Exception:  # noqa: BLE001 (no LLVM)
        return ms.import_mitsuba("scalar_rgb")


def test_every_variant_loads_and_renders(mi):
    for variant in VARIANTS:
        scene = ms.load_scene(mi, width=16, height=16, spp=4, max_depth=5,
                              scene="cornell-box" + (":" + variant if variant else ""))
        assert len(scene.emitters()) == 1
        img = ms.render(mi, scene, 4, seed=0)
        assert np.isfinite(img).all() and img.mean() > 0.01, variant
