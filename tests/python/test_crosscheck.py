"""tools/crosscheck.py's judgement (no Mitsuba needed): the suite's per-pixel z-test
with a Sidak-corrected level, exact agreement where neither side has variance, and the
per-channel mean rule."""
import numpy as np

import crosscheck


def noisy(mean, var, seed):
    rng = np.random.default_rng(seed)
    return (mean + rng.normal(0.0, np.sqrt(var), mean.shape)).astype(np.float32)


def test_two_noisy_renders_of_one_image_pass():
    truth = np.full((24, 32, 3), 0.4)
    var = np.full(truth.shape, 1e-4, dtype=np.float32)
    summary, z = crosscheck.compare(noisy(truth, 1e-4, 1), var, noisy(truth, 1e-4, 2), var, 0.02)
    assert summary["pass"] and summary["share_passed"] >= 0.99
    assert z.shape == truth.shape and np.isfinite(z).all()


def test_a_wrong_albedo_on_part_of_the_image_fails():
    truth = np.full((24, 32, 3), 0.4)
    wrong = truth.copy()
    wrong[:, :8, 0] *= 0.5  # a wall's red halved
    var = np.full(truth.shape, 1e-4, dtype=np.float32)
    summary, _ = crosscheck.compare(noisy(wrong, 1e-4, 1), var, noisy(truth, 1e-4, 2), var, 0.02)
    assert not summary["pass"]
    assert summary["share_passed"] < 0.99 and summary["mean_ratio"][0] < 0.95


def test_values_without_variance_must_agree_exactly():
    ours = np.full((2, 2, 3), 10.0, dtype=np.float32)  # a directly seen light
    zero = np.zeros_like(ours)
    summary, _ = crosscheck.compare(ours, zero, ours.copy(), zero, 0.02)
    assert summary["pass"] and summary["zero_variance"] == ours.size
    off = ours * 1.01
    summary, z = crosscheck.compare(off, zero, ours, zero, 0.02)
    assert not summary["pass"] and summary["zero_variance_failed"] == ours.size and np.isinf(z).all()
