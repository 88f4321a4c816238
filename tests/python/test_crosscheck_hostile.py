"""tools/crosscheck.py's exit contract on hostile input (issue 34), with a stand-in
`mitsuba` package: 0 same, 1 different, 2 bad input (one line, nothing written), 3 an
internal failure (one line, no traceback). Exit 1 must never stand for a crash."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mitsuba_scene as ms

TOOLS = Path(__file__).resolve().parents[2] / "tools"

# A stand-in Mitsuba: a scene file's text picks what it does. "no-integrator": the
# scene has none and render() without one raises as Mitsuba 3.9 does ("No integrator
# specified!"); "raise": render() raises a plain Exception; "luminance": a one-channel film.
FAKE = '''
import numpy as np
class _Scene:
    def __init__(self, text): self.text = text
    def integrator(self): return None if "no-integrator" in self.text else "theirs"
def set_variant(v):
    if v == "bogus": raise ImportError('Requested an unsupported variant "bogus".')
def load_file(path):
    return _Scene(open(path).read())
def load_dict(d):
    assert d["type"] == "path"
    return ("pathbench", d["max_depth"])
def render(scene, integrator=None, spp=1, seed=0):
    if "raise" in scene.text: raise Exception("plugin exploded\\nsecond line")
    if (integrator or scene.integrator()) is None: raise Exception("No integrator specified!")
    img = np.ones((2, 2, 1 if "luminance" in scene.text else 4), np.float32)
    return img + np.random.default_rng(seed).normal(0, 1e-3, img.shape).astype(np.float32)
'''


def _crosscheck(tmp_path, scene_text, *extra, image=None):
    fake = tmp_path / "fake" / "mitsuba"
    fake.mkdir(parents=True, exist_ok=True)
    (fake / "__init__.py").write_text(FAKE)
    (tmp_path / "scene.xml").write_text(scene_text)
    img = np.ones((2, 2, 3), np.float32) if image is None else image
    ms.write_pfm(tmp_path / "pathbench-cpu.pfm", img)
    ms.write_pfm(tmp_path / "pathbench-cpu-var.pfm", np.full(img.shape, 1e-4, np.float32))
    env = dict(os.environ, PYTHONPATH=f"{tmp_path / 'fake'}{os.pathsep}{TOOLS}")
    args = ["--xml", str(tmp_path / "scene.xml"), "--image", f"cpu={tmp_path / 'pathbench-cpu.pfm'}",
            "--out-dir", str(tmp_path / "out"), "--passes", "4", "--spp", "8", *extra]
    return subprocess.run([sys.executable, str(TOOLS / "crosscheck.py"), *args], capture_output=True, text=True,
                          env=env, timeout=120)


def _bad_input(r, needle):
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("crosscheck.py: error: ") and needle in lines[0], r.stderr
    assert "Traceback" not in r.stderr


def test_a_scene_without_integrator_gets_pathbench_s(tmp_path):
    r = _crosscheck(tmp_path, "no-integrator", "--bounces", "2")
    assert r.returncode in (0, 1), r.stderr
    assert (tmp_path / "out" / "verdict.json").is_file() and "Traceback" not in r.stderr


def test_a_one_channel_film_is_compared_as_grey(tmp_path):
    r = _crosscheck(tmp_path, "luminance")
    assert r.returncode in (0, 1), r.stderr


def test_mitsuba_failing_to_render_is_bad_input_and_writes_nothing(tmp_path):
    r = _crosscheck(tmp_path, "raise")
    _bad_input(r, "Mitsuba cannot render")
    assert "second line" not in r.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("extra, needle", [
    (["--spp", "0"], "--spp 0: must be 1 to 4294967295"),
    (["--spp", str(2**32)], "--spp 4294967296"),
    (["--passes", "100000"], "--passes 100000"),
    (["--mean-tolerance", "nan"], "--mean-tolerance nan"),
    (["--image", "../../escape=x.pfm"], "DEVICE of a-z"),
    (["--image", "cpu=/nonexistent/x.pfm"], "x.pfm"),
    (["--variant", "bogus"], "--variant bogus"),
])
def test_bad_options_are_bad_input(tmp_path, extra, needle):
    _bad_input(_crosscheck(tmp_path, "plain", *extra), needle)
    assert not (tmp_path / "out").exists()


def test_out_dir_naming_a_file(tmp_path):
    (tmp_path / "out").write_text("mine")
    _bad_input(_crosscheck(tmp_path, "plain"), "is a file")
    assert (tmp_path / "out").read_text() == "mine"


@pytest.mark.parametrize("content, needle", [
    (b"PF\n", "header ends"),                      # looped forever
    (b"PF\n2 2\n-1.0\n" + b"\0" * 7, "PFM data is 7 bytes"),
    (b"PF\n99999999 99999999\n-1.0\n", "not supported"),
    (b"PF\n-2 2\n-1.0\n", "not supported"),
    (b"PF\n2 2\nnan\n", "not supported"),
    (b"PF\nx y\n-1\n", "malformed PFM header"),
])
def test_hostile_pfm_headers(tmp_path, content, needle):
    p = tmp_path / "bad.pfm"
    p.write_bytes(content)
    with pytest.raises(ValueError, match=needle):
        ms.read_pfm(p)
