"""load_scene's warnings: what a scene file holds that pathbench does not model is a
Python UserWarning (not only a line on the C-level stderr), and strict=True makes it a
ValueError, as `render --strict` makes it exit 2."""
import os
import warnings

import pytest

try:
    import pathbench
except ImportError as e:
    if os.environ.get("CI"):
        raise
    pytest.skip(f"{e} (scripts/build.sh)", allow_module_level=True)

MTL = """newmtl light
Kd 0 0 0
Ke 10 10 10
newmtl wood
Kd 0.6 0.4 0.2
map_Kd wood.png
"""
OBJ = """mtllib box.mtl
v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
v -0.2 2 -0.2
v 0.2 2 -0.2
v 0.2 2 0.2
v -0.2 2 0.2
usemtl wood
f 1 2 3
f 1 3 4
usemtl light
f 5 7 6
f 5 8 7
"""


@pytest.fixture
def textured_obj(tmp_path):
    (tmp_path / "box.mtl").write_text(MTL)
    (tmp_path / "box.obj").write_text(OBJ)
    return str(tmp_path / "box.obj")


def test_unmodelled_texture_is_a_user_warning(textured_obj):
    with pytest.warns(UserWarning, match=r"box\.obj: material 'wood': texture map_Kd 'wood.png' \(not modelled"):
        scene = pathbench.load_scene(textured_obj)
    assert scene.num_triangles == 4


def test_strict_refuses_what_is_not_modelled(textured_obj):
    with pytest.raises(ValueError, match=r"texture map_Kd 'wood.png': not modelled by pathbench \(--strict\)"):
        pathbench.load_scene(textured_obj, strict=True)


def test_warnings_as_errors_raise(textured_obj):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="map_Kd"):
            pathbench.load_scene(textured_obj)


def test_builtin_scene_says_nothing():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pathbench.load_scene("paper-cornell", strict=True)


def test_default_light_is_a_note(tmp_path):
    (tmp_path / "dark.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.warns(UserWarning, match=r"^note: .*dark\.obj: no emissive material"):
        pathbench.load_scene(str(tmp_path / "dark.obj"))
