"""tools/crosscheck.py's judgement (no Mitsuba needed): the suite's per-pixel z-test
with a Sidak-corrected level, exact agreement where neither side has variance, and the
per-channel mean rule."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import crosscheck
import mitsuba_scene as ms

TOOLS = Path(__file__).resolve().parents[2] / "tools"


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


def _run_with_fake_mitsuba(tmp_path, init_text):
    """crosscheck.py with a stand-in `mitsuba` package first on the path."""
    fake = tmp_path / "fake" / "mitsuba"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text(init_text)
    image = np.ones((2, 2, 3), np.float32)
    ms.write_pfm(tmp_path / "pathbench-cpu.pfm", image)
    ms.write_pfm(tmp_path / "pathbench-cpu-var.pfm", image * 0)
    env = dict(os.environ, PYTHONPATH=f"{tmp_path / 'fake'}{os.pathsep}{TOOLS}")
    return subprocess.run([sys.executable, str(TOOLS / "crosscheck.py"), "--xml", str(tmp_path / "scene.xml"),
                           "--image", f"cpu={tmp_path / 'pathbench-cpu.pfm'}", "--out-dir", str(tmp_path / "out")],
                          capture_output=True, text=True, env=env, timeout=60)


def test_a_mitsuba_that_fails_to_load_is_not_called_missing(tmp_path):
    r = _run_with_fake_mitsuba(tmp_path, "raise ImportError('undefined symbol: rtcOccluded4')\n")
    assert r.returncode == 2, r.stderr
    assert "Mitsuba 3 is installed but failed to load (undefined symbol: rtcOccluded4)" in r.stderr
    assert "not installed" not in r.stderr
    assert not (tmp_path / "out").exists()
