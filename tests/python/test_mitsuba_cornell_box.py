"""tools/mitsuba_cornell_box.py and mitsuba_scene.material_bsdf: pathbench's cornell-box
variants as Mitsuba 3 scenes, each material exported as the Mitsuba plugin pathbench's
BSDF of that kind is defined as. The data tests need no Mitsuba; the rest skip without it."""
import numpy as np
import pytest

import mitsuba_cornell_box as cb
import mitsuba_scene as ms


def normals(verts, faces):
    v = np.asarray(verts, dtype=float)
    f = np.asarray(faces)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_room_and_blocks_as_pathbench():
    parts = {name: (verts, faces, m) for name, verts, faces, m in cb.parts("")}
    assert sum(len(f) for _, f, _ in parts.values()) == 38  # as pathbench's `cornell-box`
    assert np.allclose(normals(*parts["light"][:2]), [0, -1, 0])
    assert parts["light"][2]["emission"] == (17.0, 12.0, 4.0)


@pytest.mark.parametrize("variant, kinds", [
    ("mirror", {"diffuse", "mirror"}), ("glass", {"diffuse", "dielectric"}),
    ("spheres", {"diffuse", "mirror", "dielectric"}), ("ggx", {"diffuse", "roughconductor"})])
def test_variants_use_their_kinds(variant, kinds):
    assert {m["kind"] for *_, m in cb.parts(variant)} == kinds


def test_icosphere_is_closed_outward_and_on_the_sphere():
    verts, faces = cb.icosphere((1.0, 2.0, 3.0), 2.0, 3)
    assert len(faces) == 20 * 4 ** 3 and len(verts) == 10 * 4 ** 3 + 2
    v = np.asarray(verts)
    assert np.allclose(np.linalg.norm(v - [1, 2, 3], axis=1), 2.0, rtol=1e-6)
    f = np.asarray(faces)
    centres = v[f].mean(axis=1) - [1, 2, 3]
    assert (np.einsum("ij,ij->i", normals(verts, faces), centres) > 0).all(), "normals point outwards"
    edges = {}
    for a, b, c in faces:
        for e in ((a, b), (b, c), (c, a)):
            edges[tuple(sorted(e))] = edges.get(tuple(sorted(e)), 0) + 1
    assert set(edges.values()) == {2}, "every edge shared by two triangles: closed"


def test_unknown_variant():
    with pytest.raises(ValueError, match="unknown variant"):
        cb.parts("chrome")


def test_material_export_matches_mitsubas_plugins():
    assert ms.material_bsdf(cb.WHITE) == {"type": "twosided", "material": ms._bsdf((0.75, 0.75, 0.75))}
    mirror = ms.material_bsdf(cb.MIRROR)["material"]
    assert mirror["type"] == "conductor" and mirror["material"] == "none"
    glass = ms.material_bsdf(cb.GLASS)
    assert glass["type"] == "dielectric" and glass["int_ior"] == 1.5 and glass["ext_ior"] == 1.0
    rough = ms.material_bsdf(cb.COPPER)["material"]
    assert (rough["type"], rough["distribution"], rough["alpha"], rough["material"]) == \
        ("roughconductor", "ggx", 0.2, "none")


@pytest.fixture(scope="module")
def mi():
    pytest.importorskip("mitsuba", reason="mitsuba is not installed")
    try:
        return ms.import_mitsuba("llvm_ad_rgb")
    except Exception:  # noqa: BLE001 (no LLVM)
        return ms.import_mitsuba("scalar_rgb")


def test_every_variant_loads_and_renders(mi):
    for variant in cb.VARIANTS:
        scene = ms.load_scene(mi, width=16, height=16, spp=4, max_depth=5,
                              scene="cornell-box" + (":" + variant if variant else ""))
        assert len(scene.emitters()) == 1
        img = ms.render(mi, scene, 4, seed=0)
        assert np.isfinite(img).all() and img.mean() > 0.01, variant
