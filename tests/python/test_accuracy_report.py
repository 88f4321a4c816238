"""tools/accuracy_report.py: the tonemap FLIP sees, FLIP itself on known images, the
log-log interpolation of the time to reach an error, and a whole run on a synthetic
`pathbench accuracy` result (table, plots, FLIP written back into the JSON)."""
import json

import numpy as np
import pytest

import accuracy_report as ar
from mitsuba_scene import write_pfm


def test_tonemap_clamps_and_encodes_srgb():
    x = np.array([[[-1.0, 0.0, 0.002]], [[0.5, 1.0, 7.0]]], dtype=np.float32)
    t = ar.tonemap_srgb(x)
    assert t.min() == 0.0 and t.max() == pytest.approx(1.0)
    assert t[0, 0, 2] == pytest.approx(12.92 * 0.002)
    assert t[1, 0, 0] == pytest.approx(1.055 * 0.5 ** (1 / 2.4) - 0.055)


def test_flip_is_zero_for_identical_images_and_grows_with_noise():
    rng = np.random.default_rng(3)
    ref = rng.uniform(0.1, 0.9, size=(48, 48, 3)).astype(np.float32)
    assert ar.flip_mean(ref, ref) == pytest.approx(0.0, abs=1e-6)
    small = ar.flip_mean(ref, ref + rng.normal(0, 0.02, ref.shape).astype(np.float32))
    large = ar.flip_mean(ref, ref + rng.normal(0, 0.2, ref.shape).astype(np.float32))
    assert 0 < small < large <= 1


def test_seconds_to_reach_interpolates_log_log():
    rows = [{"seconds": 1.0, "rel_mse": 1.0}, {"seconds": 4.0, "rel_mse": 0.25}, {"seconds": 16.0, "rel_mse": 0.0625}]
    # error ~ 1/t: 0.1 is reached at t = 10, between the 2nd and 3rd rungs.
    assert ar.seconds_to_reach(rows, "rel_mse", 0.1) == pytest.approx(10.0)
    assert ar.seconds_to_reach(rows, "rel_mse", 1e-3) is None
    assert ar.seconds_to_reach(rows, "rel_mse", 2.0) is None


def synthetic_run(tmp_path):
    """A result as `pathbench accuracy` writes it: a reference and two configurations,
    one unbiased (noise that shrinks with spp), one 20% too dark."""
    rng = np.random.default_rng(5)
    ref = rng.uniform(0.05, 1.5, size=(16, 24, 3)).astype(np.float32)
    write_pfm(tmp_path / "ref.pfm", ref)
    rows = []
    for name, scale in (("baseline", 1.0), ("bounces-1", 0.8)):
        for i, spp in enumerate((1, 4, 16)):
            img = (scale * ref + rng.normal(0, 0.3 / np.sqrt(spp), ref.shape)).astype(np.float32)
            rel = f"images/x/{name}-{spp}spp.pfm"
            write_pfm(tmp_path / rel, img)
            err = float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01)))
            bias = float(img.mean() / ref.mean() - 1)
            se = None if spp == 1 else float(0.3 / np.sqrt(spp) / np.sqrt(ref.size) / ref.mean())
            rows.append({"config": name, "spp": spp, "seconds": 0.01 * 4 ** i, "rays": 1000 * 4 ** i,
                         "rays_per_second": 1e5, "rmse": float(np.sqrt(np.mean((img - ref) ** 2))), "rel_mse": err,
                         "bias": bias, "bias_stderr": se, "bias_z": None if se is None else bias / se,
                         "biased": None if se is None else bool(abs(bias / se) > 4),
                         "efficiency": 1 / (err * 0.01 * 4 ** i), "image": rel})
    res = {
        "scene": "synthetic", "width": 24, "height": 16, "device": "cpu", "strategy": "pixel", "seed": 1,
        "date": "2026-01-01 00:00 UTC", "git_revision": "abc", "compiler": "gcc",
        "machine": {"slug": "x", "cpu": "Test CPU", "hardware_threads": 2, "threads": 2},
        "load_average_at_start": [0.1, 0.1, 0.1], "load_average_at_end": [1.0, 1.0, 1.0],
        "ladder": {"max_spp": 16, "max_seconds": 5, "factor": 4},
        "metrics": {"rmse": "r", "rel_mse": "m", "rel_mse_eps": 0.01, "bias": "b", "bias_z_threshold": 4,
                    "efficiency": "1 / (rel_mse x seconds)", "seconds": "wall"},
        "reference": {"file": "ref.pfm", "spp": 256, "seconds": 1.5, "cached": False, "rel_mse_floor": 1e-4,
                      "precision": "double"},
        "configurations": [
            {"name": "baseline", "label": "unbounded", "groups": ["bounces", "precision"]},
            {"name": "bounces-1", "label": "one bounce", "groups": ["bounces"]},
        ],
        "rows": rows, "skipped": [{"config": "double", "reason": "the GPU runs float only"}],
    }
    path = tmp_path / "synthetic-24x16-cpu.json"
    path.write_text(json.dumps(res))
    return path


def test_whole_run_writes_table_plots_and_flip(tmp_path):
    path = synthetic_run(tmp_path)
    assert ar.main([str(path)]) == 0
    res = json.loads(path.read_text())
    flips = {(r["config"], r["spp"]): r["flip"] for r in res["rows"]}
    assert all(0 < f < 1 for f in flips.values())
    assert flips[("baseline", 16)] < flips[("baseline", 1)]  # less noise, less visible error
    for suffix in ("-error-vs-time.png", "-flip-vs-time.png", "-bias.png", "-reference.png"):
        assert (tmp_path / f"synthetic-24x16-cpu{suffix}").stat().st_size > 1000
    md = (tmp_path / "synthetic-24x16-cpu.md").read_text()
    assert "| one bounce | 16 |" in md
    assert "**biased**" in md            # the 20% dark configuration
    assert "skipped: the GPU runs float only" in md
    assert "## Bounce budget" in md and "## Path-step precision" in md
    assert "## Sampling" not in md       # no configuration in that group
    assert "ran on CPU, 2 threads" in md


def test_missing_images_leave_flip_out(tmp_path):
    path = synthetic_run(tmp_path)
    for p in (tmp_path / "images" / "x").iterdir():
        p.unlink()
    assert ar.main([str(path)]) == 0
    res = json.loads(path.read_text())
    assert all("flip" not in r for r in res["rows"])
    assert "FLIP" in (tmp_path / "synthetic-24x16-cpu.md").read_text()
