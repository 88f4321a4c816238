"""`pathbench crosscheck` stopped by a signal (issue 34): it dies by that signal (the
shell's 130 for SIGINT, 143 for SIGTERM) and leaves nothing it created in --out-dir —
neither the exported scene while pathbench renders nor pathbench's finished .pfm
images while Mitsuba renders (both stayed before: the signal ended the process at
once). Mitsuba is a stand-in whose render() marks that it started and then sleeps, so
the signal lands in the phase each test names; the terminal's Ctrl-C is a SIGINT to
the whole process group."""
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PATHBENCH = ROOT / "build" / "bin" / "pathbench"

FAKE = '''
import os, signal, time
import numpy as np
class _Scene:
    def integrator(self): return "theirs"
def set_variant(v): pass
def load_file(path): return _Scene()
def load_dict(d): return d
_stopped = []
def render(scene, integrator=None, spp=1, seed=0):
    open(os.environ["FAKE_MITSUBA_STARTED"], "w").close()
    if os.environ.get("FAKE_MITSUBA_WINDS_DOWN"):
        # As Mitsuba 3.9 does: its own SIGINT handler during render() ends the render early
        # ("Received interrupt signal, winding down..") and returns the partial image.
        old = signal.signal(signal.SIGINT, lambda *a: _stopped.append(1))
        end = time.monotonic() + 120
        while not _stopped and time.monotonic() < end:
            time.sleep(0.01)
        signal.signal(signal.SIGINT, old)
        return np.full((8, 8, 3), 0.5, np.float32) + np.float32(seed) * 1e-3
    time.sleep(120)
    return np.ones((4, 4, 3), np.float32)
'''

pytestmark = pytest.mark.skipif(not PATHBENCH.exists(), reason="needs build/bin/pathbench")


def _start(tmp_path, out, *size, **env_more):
    fake = tmp_path / "fake" / "mitsuba"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text(FAKE)
    env = dict(os.environ, PYTHONPATH=str(tmp_path / "fake"), FAKE_MITSUBA_STARTED=str(tmp_path / "started"),
               **env_more)
    # A new session: the test's SIGINT to the group stands for the terminal's Ctrl-C.
    # Output to files, not pipes: a child left running would hold a pipe open.
    with open(tmp_path / "stdout", "w") as o, open(tmp_path / "stderr", "w") as e:
        p = subprocess.Popen([str(PATHBENCH), "crosscheck", "paper-cornell", "--out-dir", str(out), "--threads", "1",
                              "--device", "cpu", *size], env=env, start_new_session=True, stdout=o, stderr=e)
    p.tmp = tmp_path
    STARTED.append(p)
    return p


STARTED = []


@pytest.fixture(autouse=True)
def _kill_leftovers():
    yield
    while STARTED:  # whatever a failed test left running (the group outlives its leader)
        try:
            os.killpg(STARTED.pop().pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def _wait_for(path: Path, p, seconds=120):
    end = time.monotonic() + seconds
    while not path.exists():
        assert p.poll() is None, f"crosscheck ended first: {p.returncode} {(p.tmp / 'stderr').read_text()}"
        assert time.monotonic() < end, f"{path} never appeared"
        time.sleep(0.005)


def _stopped(p, sig):
    p.wait(timeout=120)
    err = (p.tmp / "stderr").read_text()
    assert p.returncode == -sig, (p.returncode, err)  # died by the signal: 128 + N in a shell
    assert "Traceback" not in err, err
    return err


def _no_child_left(tmp_path):
    # The stand-in would sleep on; it must have been stopped with the run.
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                if str(tmp_path / "fake") in (d / "environ").read_bytes().decode(errors="replace"):
                    pytest.fail(f"process {d.name} of this run still runs")
            except OSError:
                pass


def test_ctrl_c_while_mitsuba_renders_removes_pathbench_s_images(tmp_path):
    out = tmp_path / "out"
    p = _start(tmp_path, out, "--width", "8", "--height", "8", "--spp", "4")
    _wait_for(tmp_path / "started", p)
    assert (out / "pathbench-cpu.pfm").exists() and (out / "mitsuba").is_dir()
    os.killpg(p.pid, signal.SIGINT)
    err = _stopped(p, signal.SIGINT)
    assert "SIGINT: stopped" in err, err
    assert not out.exists(), sorted(str(q.relative_to(out)) for q in out.rglob("*"))
    _no_child_left(tmp_path)


def test_sigterm_to_pathbench_alone_stops_mitsuba_too_and_keeps_what_was_there(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("kept")
    p = _start(tmp_path, out, "--width", "8", "--height", "8", "--spp", "4")
    _wait_for(tmp_path / "started", p)
    p.send_signal(signal.SIGTERM)  # only to pathbench: it passes it on to the Python tool
    _stopped(p, signal.SIGTERM)
    assert sorted(q.name for q in out.iterdir()) == ["mine.txt"]
    _no_child_left(tmp_path)


def test_ctrl_c_while_pathbench_renders_removes_the_exported_scene(tmp_path):
    out = tmp_path / "out"
    # Large enough that the render is still running when the signal comes (the folder
    # is checked for either phase: nothing may be left in any case).
    p = _start(tmp_path, out, "--width", "512", "--height", "512", "--spp", "64")
    _wait_for(out / "mitsuba" / "scene.xml", p)
    os.killpg(p.pid, signal.SIGINT)
    _stopped(p, signal.SIGINT)
    assert not (tmp_path / "started").exists(), "the render had finished: make it larger"
    assert not out.exists(), sorted(str(q.relative_to(out)) for q in out.rglob("*"))


def test_ctrl_c_that_mitsuba_takes_leaves_no_verdict_of_a_partial_render(tmp_path):
    out = tmp_path / "out"
    p = _start(tmp_path, out, "--width", "8", "--height", "8", "--spp", "4", FAKE_MITSUBA_WINDS_DOWN="1")
    _wait_for(tmp_path / "started", p)
    os.killpg(p.pid, signal.SIGINT)  # Mitsuba ends early, crosscheck.py judges what it got
    _stopped(p, signal.SIGINT)
    assert not out.exists(), sorted(str(q.relative_to(out)) for q in out.rglob("*"))

