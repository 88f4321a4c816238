"""tests/data/paper-cornell-nee-ref*.pfm (tools/make_reference.py): the committed
Mitsuba 3 reference is what tests/data/README.md says it is."""
import json
from pathlib import Path

import numpy as np
import pytest

import mitsuba_scene as ms

DATA = Path(__file__).resolve().parents[2] / "tests" / "data"


@pytest.fixture(scope="module")
def ref():
    mean = ms.read_pfm(DATA / "paper-cornell-nee-ref.pfm")
    var = ms.read_pfm(DATA / "paper-cornell-nee-ref-var.pfm")
    meta = json.loads((DATA / "paper-cornell-nee-ref.json").read_text())
    return mean, var, meta


def test_shape_and_values(ref):
    mean, var, meta = ref
    assert mean.shape == var.shape == (256, 256, 3)
    assert np.isfinite(mean).all() and np.isfinite(var).all()
    assert (mean >= 0).all() and (var >= 0).all()
    assert meta["width"] == meta["height"] == 256
    assert meta["spp_total"] == meta["passes"] * meta["spp_per_pass"]
    assert meta["passes"] >= 16 and meta["spp_total"] >= 4096
    assert mean.reshape(-1, 3).mean(axis=0) == pytest.approx(meta["image_mean_rgb"], rel=1e-5)


def test_directly_seen_light_is_exactly_ten_with_zero_variance(ref):
    mean, var, _ = ref
    light = (mean == 10.0).all(axis=2)
    assert light.sum() > 1000
    assert (var[light] == 0).all()
    rows = np.where(light.any(axis=1))[0]
    assert rows.max() < 64, "the light is at the top of the image (row 0 at the top)"


def test_red_left_green_right(ref):
    mean, _, _ = ref
    left, right = mean[:, :16].mean(axis=(0, 1)), mean[:, -16:].mean(axis=(0, 1))
    assert left[0] > 5 * left[1] and right[1] > 5 * right[0]


def test_noise_is_small(ref):
    mean, var, meta = ref
    rel = np.sqrt(var) / np.maximum(mean, 1e-6)
    lit = mean > 0.01
    assert np.median(rel[lit]) < 0.02
    assert meta["median_relative_std_error"] < 0.02
