"""The `pathbench` Python module's interface: arrays, argument checks, render."""
import os

import numpy as np
import pytest

try:
    import pathbench
except ImportError as e:
    if os.environ.get("CI"):  # CI builds the module (scripts/test.sh): missing is a failure
        raise
    pytest.skip(f"{e} (scripts/build.sh)", allow_module_level=True)


@pytest.fixture(scope="module")
def box():
    return pathbench.load_scene("paper-cornell")


def test_scene_arrays(box):
    assert box.positions.dtype == np.float32 and box.positions.shape[1] == 3
    assert box.triangles.dtype == np.uint32 and box.triangles.shape == (box.num_triangles, 3)
    assert not box.positions.flags.writeable
    lo, hi = box.bounds
    assert np.allclose(lo, box.positions.min(0)) and np.allclose(hi, box.positions.max(0))
    assert "paper-cornell" in {name for name, _ in pathbench.builtin_scenes()}


def test_scale_and_offset_move_every_point(box):
    moved = pathbench.load_scene("paper-cornell", scale=1e-4, offset=(1, 2, 3))
    assert np.allclose(moved.positions, box.positions * np.float32(1e-4) + np.float32([1, 2, 3]), rtol=1e-6)


@pytest.mark.parametrize("backend", ["embree", "bvh"])
def test_rays_along_the_axes(box, backend):
    o = np.zeros((3, 3), np.float32)
    d = np.eye(3, dtype=np.float32) * np.float32([[1], [2], [4]])
    lo, hi = box.bounds
    r = box.intersect(o, d, backend=backend)
    assert r["hit"].all() and r["prim"].dtype == np.uint32
    assert np.allclose(r["t"], hi / np.float32([1, 2, 4]), rtol=1e-6)  # t in units of |d|
    miss = box.intersect(o, d, tfar=r["t"] * 0.5, backend=backend)
    assert not miss["hit"].any() and (miss["prim"] == pathbench.NO_HIT).all() and np.isinf(miss["t"]).all()
    assert box.occluded(o, d, backend=backend).all()
    assert not box.occluded(o, d, tfar=np.float32(0.5) * r["t"], backend=backend).any()


@pytest.mark.parametrize("backend", ["embree", "bvh"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_moved_scene_speaks_user_coordinates(box, backend, dtype):
    # Moved by 1e5 the scene is traced next to the origin (finalize rebases it), but
    # positions, bounds and ray origins stay in the user's coordinates, exactly.
    shift = np.float32([1e5, -3e4, 7e4])
    moved = pathbench.load_scene("paper-cornell", offset=tuple(float(x) for x in shift))
    assert np.array_equal(moved.positions, box.positions + shift)
    assert not moved.positions.flags.writeable
    assert np.array_equal(moved.bounds, box.bounds + shift)
    o = np.zeros((3, 3), dtype) + shift.astype(dtype)
    d = np.eye(3, dtype=dtype) * dtype(2)
    r = moved.intersect(o, d, backend=backend)
    ref = box.intersect(np.zeros((3, 3), np.float32), d.astype(np.float32), backend=backend)
    assert r["hit"].all() and np.array_equal(r["prim"], ref["prim"])
    assert np.allclose(r["t"], ref["t"], rtol=1e-6)
    assert moved.occluded(o, d, backend=backend).all()


@pytest.mark.parametrize("call, message", [
    (lambda s: s.intersect(np.zeros((2, 2)), np.ones((2, 2))), "shape (N, 3)"),
    (lambda s: s.intersect(np.zeros((2, 3)), np.ones((3, 3))), "same number of rows"),
    (lambda s: s.intersect(np.full((1, 3), np.nan), np.ones((1, 3))), "origins[0] is not finite"),
    (lambda s: s.intersect(np.zeros((1, 3)), np.zeros((1, 3))), "directions[0] is zero"),
    (lambda s: s.intersect(np.zeros((1, 3)), np.ones((1, 3)), tfar=np.nan), "tfar[0]"),
    (lambda s: s.intersect(np.zeros((2, 3)), np.ones((2, 3)), tnear=np.zeros(3)), "tnear"),
    (lambda s: s.intersect(np.zeros((1, 3)), np.ones((1, 3)), tnear=0.1, backend="bvh"), "tnear = 0 only"),
    (lambda s: s.intersect(np.zeros((1, 3)), np.ones((1, 3)), backend="optix"), "backend"),
    (lambda s: s.occluded(np.zeros((1, 3)), np.ones((1, 3)), backend="bvh", watertight=False), "watertight"),
    (lambda s: pathbench.load_scene("no-such-scene"), "no-such-scene"),
    (lambda s: pathbench.load_scene("paper-cornell", scale=0), "scale"),
    (lambda s: pathbench.render(s, 0, 8, 1), "width"),
    (lambda s: pathbench.render(s, 8, 8, 1, sampling="magic"), "sampling"),
])
def test_bad_input_raises_value_error(box, call, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")
                       .replace("]", r"\]")):
        call(box)


def test_render_returns_image_and_report(box):
    image, report = pathbench.render(box, 16, 8, 4, seed=3)
    assert image.shape == (8, 16, 3) and image.dtype == np.float32 and np.isfinite(image).all()
    assert image.mean() > 0
    assert report["width"] == 16 and report["spp"] == 4 and report["rays"]["camera"] == 16 * 8 * 4
    again, _ = pathbench.render(box, 16, 8, 4, seed=3, strategy="wavefront")
    assert np.array_equal(image, again)  # same seed, same image, whatever the strategy
