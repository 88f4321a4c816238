"""The render report's energy record (run/src/energy_meter.cpp): null with the reason where RAPL is
absent or unreadable, 0 J for a counter that does not advance, and a counter that wraps during
the render counted across the wrap, never negative or counted from 0."""
import os
import subprocess
import threading
import time

import pytest

from test_suite import PATHBENCH, needs_build, strict_load


def render_energy(tmp_path, powercap_root):
    """A small CPU render with RAPL read under `powercap_root`; its report's energy record."""
    out = tmp_path / "r.json"
    args = [str(PATHBENCH), "render", "--scene", "paper-cornell", "--width", "16", "--height", "16", "--spp", "2",
            "--report", str(out)]
    r = subprocess.run(args, capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, PATHBENCH_POWERCAP_ROOT=str(powercap_root)))
    assert r.returncode == 0, r.stderr
    report = strict_load(out)
    return report["energy"], report["rays"]["total"]


def fifo_zone(root):
    """A fake package domain under `root` whose energy_uj is a FIFO."""
    zone = root / "intel-rapl:0"
    zone.mkdir(parents=True)
    (zone / "max_energy_range_uj").write_text("1000000\n")
    (zone / "name").write_text("package-0\n")
    os.mkfifo(zone / "energy_uj")
    return zone / "energy_uj"


def feed(fifo, values):
    """Hands `values` to the FIFO's readers, one per open, pausing so that a reader closes before
    the next open (on a loaded machine it may not: the tests below allow for it)."""
    def run():
        try:
            for v in values:
                with open(fifo, "w") as f:
                    f.write(v)
                time.sleep(1.5)
        except BrokenPipeError:  # released by release() after a render that read out of step
            pass
    t = threading.Thread(target=run, daemon=True)
    t.start()
    return t


def release(fifo, feeder):
    os.close(os.open(fifo, os.O_RDONLY | os.O_NONBLOCK))  # frees a feeder left waiting for a reader
    feeder.join(5)


@needs_build
def test_energy_null_without_rapl_and_zero_for_a_still_counter(tmp_path):
    e, _ = render_energy(tmp_path, tmp_path / "none")
    assert e["joules"] is None and "does not exist" in e["reason"] and e["source"] == "rapl"
    # A counter that reads near its maximum and is not advancing: 0 J, not "max_range" J.
    zone = tmp_path / "powercap" / "intel-rapl:0"
    zone.mkdir(parents=True)
    (zone / "energy_uj").write_text("999990\n")
    (zone / "max_energy_range_uj").write_text("1000000\n")
    (zone / "name").write_text("package-0\n")
    (tmp_path / "powercap" / "intel-rapl:0:0").mkdir()  # a sub-zone (core, dram): not counted
    e, _ = render_energy(tmp_path, tmp_path / "powercap")
    assert e["joules"] == 0 and e["rays_per_joule"] is None


@needs_build
def test_energy_null_when_the_start_reads_no_number(tmp_path):
    """A counter readable at the probe but not at the start (the FIFO closes with nothing): no
    figure, the file named, never joules counted from 0."""
    fifo = fifo_zone(tmp_path / "powercap")
    feeder = feed(fifo, ["999990\n", ""])
    e, _ = render_energy(tmp_path, tmp_path / "powercap")
    release(fifo, feeder)
    assert e["joules"] is None and "energy_uj: not a number" in e["reason"] and e.get("rays_per_joule") is None, e


@needs_build
def test_energy_counts_across_the_counters_wrap(tmp_path):
    """The counter wraps during the render: 999990 (the probe), 999990 (start), then 10 (end) give
    20 uJ, not a negative or a 1 J figure. A render whose reads met the FIFO out of step must
    report null with the reason (never a figure); it is tried again, up to three times."""
    for attempt in range(3):
        fifo = fifo_zone(tmp_path / f"powercap-{attempt}")
        feeder = feed(fifo, ["999990\n", "999990\n", "10\n"])
        e, rays = render_energy(tmp_path, fifo.parent.parent)
        release(fifo, feeder)
        if e["joules"] is not None:
            assert e["joules"] == pytest.approx(20e-6) and e["source"] == "rapl", (attempt, e)
            assert e["rays_per_joule"] == pytest.approx(rays / 20e-6)
            return
        assert "energy_uj" in e["reason"] and e.get("rays_per_joule") is None, (attempt, e)
    pytest.fail("three renders in a row read the FIFO out of step: no 20 uJ figure to check")
