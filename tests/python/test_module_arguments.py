"""`pathbench`'s arguments: no silent cast, shapes and layouts, and render() taking the
CLI's options through the CLI's own validation (messages in keyword terms)."""
import os
import pathlib
import re

import numpy as np
import pytest

try:
    import pathbench
except ImportError as e:
    if os.environ.get("CI"):
        raise
    pytest.skip(f"{e} (scripts/build.sh)", allow_module_level=True)


@pytest.fixture(scope="module")
def box():
    return pathbench.load_scene("paper-cornell")


ONE = np.ones((1, 3))
ZERO = np.zeros((1, 3))


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(origins=np.zeros((1, 3), complex)), TypeError, "origins is complex"),
    (dict(directions=np.ones((1, 3), np.complex64)), TypeError, "directions is complex"),
    (dict(origins=np.zeros((1, 3), bool)), TypeError, "origins is an array of bool"),
    (dict(directions=np.array([[1, 1, object()]])), TypeError, "directions has dtype object"),
    (dict(directions=[["1", "1", "1"]]), TypeError, "directions has dtype <U1"),
    (dict(tnear=True), TypeError, "tnear is an array of bool"),
    (dict(tfar=1 + 0j), TypeError, "tfar is complex"),
    (dict(tfar=np.ones((1, 1))), ValueError, "tfar must be a number or an array of shape (1,)"),
    (dict(origins=np.zeros(3)), ValueError, "origins must have shape (N, 3), got (3,)"),
    (dict(directions=[[1, 1, 1], [1, 1]]), ValueError, "directions: not an array of numbers"),
    (dict(backend=b"embree"), TypeError, "backend must be a str"),
    (dict(watertight=1), TypeError, "watertight must be True or False, got int"),
    (dict(watertight=None), TypeError, "watertight must be True or False, got NoneType"),
])
@pytest.mark.parametrize("method", ["intersect", "occluded"])
def test_ray_arguments_are_not_cast_silently(box, method, kwargs, error, message):
    args = dict(origins=ZERO, directions=ONE) | kwargs
    with pytest.raises(error, match=re.escape(message)):
        getattr(box, method)(**args)


def test_any_real_dtype_and_any_layout_give_the_same_hits(box):
    rng = np.random.default_rng(1)
    d = rng.normal(size=(64, 3))
    o = np.tile(box.bounds.mean(0), (64, 1)).astype(np.float64)
    want = box.intersect(o.astype(np.float32), d.astype(np.float32))  # float64 rounds to float32 as numpy does
    assert want["hit"].all()
    wide = np.zeros((64, 9))
    wide[:, ::3] = d
    for same in (wide[:, ::3], np.asfortranarray(d), d.tolist(), d.T.copy().T):
        got = box.intersect(o, same)
        assert np.array_equal(got["prim"], want["prim"]) and np.array_equal(got["t"], want["t"])
    backwards = box.intersect(o[::-1], d[::-1])  # negative strides
    assert np.array_equal(backwards["t"], want["t"][::-1])
    ints = box.intersect(np.zeros((3, 3), np.int64), np.eye(3, dtype=np.uint8))
    assert np.array_equal(ints["t"], box.intersect(np.zeros((3, 3)), np.eye(3))["t"])


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(width=8.0), TypeError, "width must be an int, got float"),
    (dict(height=True), TypeError, "height must be an int, got bool"),
    (dict(spp="4"), TypeError, "spp must be an int, got str"),
    (dict(width=-1), ValueError, "width = -1 is out of range"),
    (dict(seed=-1), ValueError, "seed = -1 is out of range"),
    (dict(seed=2**64), ValueError, "seed = 18446744073709551616 is out of range"),
    (dict(paths_in_flight=-5), ValueError, "paths_in_flight = -5 is out of range"),
    (dict(spp=0), ValueError, "spp: must be at least 1"),
    (dict(width=0), ValueError, "width/height: the image must be at least 1x1"),
    (dict(threads=-2), ValueError, "threads: must be >= 0"),
    (dict(bounces=-2), ValueError, "bounces = -2 is out of range"),
    (dict(bounces=-1), ValueError, "converged without Russian roulette"),
    (dict(bounces=3, converged=True), ValueError, "bounces and converged=True exclude each other"),
    (dict(sampling="magic"), ValueError, "sampling: unknown sampling 'magic'"),
    (dict(strategy="queue"), ValueError, "strategy: unknown strategy 'queue'"),
    (dict(device="tpu"), ValueError, "device: unknown device 'tpu'"),
    (dict(precision="half"), ValueError, "precision: unknown precision 'half'"),
    (dict(embree_layout="strips"), ValueError, "embree_layout: unknown layout 'strips'"),
    (dict(embree_layout=1), TypeError, "embree_layout must be a str"),
    (dict(instancing="maybe"), ValueError, "instancing: unknown choice 'maybe' (expected auto, on or off)"),
    (dict(instancing=True), TypeError, "instancing must be a str"),
    (dict(rr=1), TypeError, "rr must be True or False"),
    (dict(variance=None), TypeError, "variance must be True or False"),
])
def test_render_arguments(box, kwargs, error, message):
    args = dict(width=4, height=4, spp=1) | kwargs
    with pytest.raises(error, match=re.escape(message)):
        pathbench.render(box, args.pop("width"), args.pop("height"), args.pop("spp"), **args)


def test_python_terms_rewords_cli_options_only():
    # The CLI's messages name options; the module's name keywords (and leave other dashes alone).
    with pytest.raises(ValueError) as e:
        pathbench.render(pathbench.load_scene("paper-cornell"), 4, 4, 1, paths_in_flight=0, embree_layout="x-y")
    assert str(e.value).startswith("embree_layout: unknown layout 'x-y'") and "--" not in str(e.value)


def test_render_takes_every_cli_option(box):
    image, report = pathbench.render(box, 8, 4, 2, converged=True, sampling="cosine", strategy="wavefront",
                                     device="cpu", precision="double", embree_layout="quads", seed=np.uint64(7),
                                     paths_in_flight=16, threads=1, watertight=False, profile=False)
    assert image.shape == (4, 8, 3) and np.isfinite(image).all()
    assert (report["sampling"], report["strategy"], report["precision"], report["embree_layout"]["used"]) == \
        ("cosine", "wavefront", "double", "quads")
    assert report["bounces"] == "unbounded" and report["russian_roulette"] is True and report["seed"] == 7
    assert report["watertight"] is False and report["paths_in_flight"] == 16
    image2, _, variance = pathbench.render(box, 8, 4, 2, variance=True, bounces=1, rr=True, seed=7)
    assert variance.shape == image2.shape and variance.dtype == np.float32 and (variance >= 0).all()


def test_instancing_keyword_gives_the_flat_image():
    # Embree instances of the example's eight cubes: the flat scene's image, and the report says so.
    scene = pathbench.load_scene(str(pathlib.Path(__file__).parents[2] / "scenes/examples/instancing.json"))
    flat, flat_report = pathbench.render(scene, 16, 12, 2, instancing="off")
    inst, inst_report = pathbench.render(scene, 16, 12, 2, instancing="on")
    assert np.array_equal(flat, inst)
    assert flat_report["instancing"]["used"] is False and inst_report["instancing"]["used"] is True
    assert inst_report["instancing"]["instances"] == 8
    assert inst_report["instancing"]["accel_bytes"] < flat_report["instancing"]["accel_bytes"]


def test_device_gpu_runs_or_says_why_not(box):
    available, why = pathbench.gpu_available()
    if available:
        image, report = pathbench.render(box, 4, 4, 1, device="gpu")
        assert report["device"] == "gpu" and image.shape == (4, 4, 3)
    else:
        assert why
        with pytest.raises(ValueError, match=re.escape(f"device gpu: {why}")):
            pathbench.render(box, 4, 4, 1, device="gpu")
