"""tools/mitsuba_speed.py (issue 35, honest ratios): enough Mitsuba renders in interleaved rounds,
the spread of every timing, the load around each render, strict JSON, and the run recorded in the
project history. The end-to-end test renders a tiny frame with both renderers."""
import json
import math
import os
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

import mitsuba_speed
import mitsuba_speed_history
import mitsuba_speed_report as report
import mitsuba_speed_runners as runners

ROOT = Path(__file__).resolve().parents[2]
EXE = ROOT / "build" / "bin" / "pathbench"


def test_spread_median_range_and_iqr():
    s = report.spread([5.0, 1.0, 3.0, 2.0, 4.0])
    assert s == {"n": 5, "median": 3.0, "min": 1.0, "max": 5.0, "q1": 2.0, "q3": 4.0, "iqr": 2.0}
    assert report.spread([7.0])["iqr"] == 0.0
    with pytest.raises(ValueError):
        report.spread([])


def test_round_speedups_take_each_rounds_medians():
    m = [{"round": 0, "seconds": 10.0}, {"round": 0, "seconds": 12.0}, {"round": 1, "seconds": 9.0},
         {"round": 1, "seconds": 9.0}, {"round": 2, "seconds": 30.0}]  # round 2: no pathbench run
    p = [{"round": 0, "seconds": 5.5}, {"round": 1, "seconds": 6.0}]
    assert report.round_speedups(m, p) == [2.0, 1.5]


def test_defaults_take_ten_mitsuba_renders_in_five_rounds():
    a = mitsuba_speed.parse_args([])
    assert a.rounds >= 5 and a.rounds * a.mitsuba_per_round >= 10


def test_bad_counts_are_refused_with_exit_2(capsys):
    with pytest.raises(SystemExit) as e:
        mitsuba_speed.parse_args(["--rounds", "0"])
    assert e.value.code == 2 and "--rounds 0: must be at least 1" in capsys.readouterr().err


def test_timed_records_the_load_before_and_after():
    rec = runners.timed(lambda: {"x": 1}, 3)
    assert rec["round"] == 3 and rec["x"] == 1 and rec["seconds"] >= 0
    for key in ("load_before", "load_after"):
        assert len(rec[key]["loadavg"]) == 3 and rec[key]["cpu_count"] == os.cpu_count()
        assert 1 <= rec[key]["usable_cpus"] <= os.cpu_count()


def test_write_json_is_strict_and_leaves_nothing_half_written(tmp_path):
    f = tmp_path / "r.json"
    report.write_json(f, {"a": 1.5})
    assert json.loads(f.read_text()) == {"a": 1.5}
    with pytest.raises(ValueError):
        report.write_json(f, {"a": math.nan})
    assert json.loads(f.read_text()) == {"a": 1.5}  # the old file stays whole
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]  # no temporary left
    umask = os.umask(0)
    os.umask(umask)
    assert f.stat().st_mode & 0o777 == 0o666 & ~umask


def _result():
    runs_m = [{"round": k, "seconds": s} for k, s in [(0, 10.0), (0, 11.0), (1, 12.0), (1, 12.0)]]
    runs_p = [{"round": 0, "seconds": 5.25}, {"round": 1, "seconds": 8.0}]
    return {
        "machine": {"slug": "test-cpu", "cpu": "Test CPU"}, "fingerprint": {"machine_id": "0123", "cpu": "Test CPU"},
        "settings": {"scene": "paper-cornell", "width": 16, "height": 16, "spp": 4, "bounces": 2, "sampling": "nee"},
        "load_average_before": [0.1, 0.1, 0.1], "load_average_after": [1.0, 1.0, 1.0],
        "mitsuba": {"renderer": "Mitsuba 3.9.1", "variant": "llvm_ad_rgb", "median_seconds": 11.5, "runs": runs_m},
        "pathbench": {"wavefront/no-watertight": {"median_seconds": 6.625, "runs": runs_p, "git_revision": "HEAD"}},
    }


def test_history_rows_hold_the_ratio_and_both_medians():
    b = mitsuba_speed_history.bench_json(_result(), "2026-01-01T00:00:00+00:00")
    assert b["context"]["fingerprint"]["machine_id"] == "0123"
    assert b["context"]["git_revision"] == "HEAD" and b["context"]["git_dirty"] is False
    rows = b["benchmarks"]
    assert [r["name"] for r in rows] == ["mitsuba/cpu/paper-cornell/16x16/spp:4/bounces:2/nee/wavefront/no-watertight"] * 2
    assert [r["repetition_index"] for r in rows] == [0, 1]
    assert rows[0]["real_time"] == 0.5 and rows[0]["speedup_vs_mitsuba"] == 2.0  # 10.5 s against 5.25 s
    assert rows[1]["real_time"] == round(8 / 12, 4) and rows[1]["time_unit"] == "ratio"
    assert rows[0]["pathbench_median_seconds"] == 6.625 and rows[0]["mitsuba_median_seconds"] == 11.5


def test_history_record_imports_the_rows(tmp_path):
    f = tmp_path / "run.bench.json"
    report.write_json(f, mitsuba_speed_history.bench_json(_result(), "2026-01-01T00:00:00+00:00"))
    db = tmp_path / "h.sqlite"
    assert mitsuba_speed_history.record(f, str(db)) == 0
    rows = sqlite3.connect(db).execute("SELECT benchmark, repetition, value, unit, counters FROM results "
                                       "ORDER BY repetition").fetchall()
    assert [(r[0].split("/")[0], r[1], r[2], r[3]) for r in rows] == [("mitsuba", 0, 0.5, "ratio"),
                                                                      ("mitsuba", 1, round(8 / 12, 4), "ratio")]
    assert json.loads(rows[0][4])["speedup_vs_mitsuba"] == 2.0
    assert mitsuba_speed_history.record(f, str(db)) == 2  # the same run twice is refused


def test_markdown_shows_the_spread_and_the_ratio_range():
    res = _result()
    res["date"], res["machine"]["hardware_threads"] = "2026-01-01 00:00 UTC", 2
    res["mitsuba"] |= {"seconds": [10.0, 11.0, 12.0, 12.0], "warmup_seconds": 1.0, "image_mean_rgb": [0.5] * 3}
    res["pathbench"]["wavefront/no-watertight"] |= {"seconds": [5.25, 8.0], "median_rays_per_second": 1e6,
                                                    "image_mean_rgb": [0.5] * 3, "compiler": "gcc"}
    mitsuba_speed.add_rates(res, mitsuba_speed.parse_args(["--size", "16", "--spp", "4"]))
    md = report.markdown(res)
    assert "| Mitsuba 3.9.1 llvm_ad_rgb | 11.50 | 10.00–12.00 | 1.25 | 4 |" in md
    assert "| pathbench cpu/wavefront/no-watertight | 6.62 | 5.25–8.00 | 1.38 | 2 |" in md
    assert "| 1.74x (1.50–2.00x) |" in md


def test_a_dirty_tree_is_recorded_at_its_commit():
    res = _result()
    res["pathbench"]["wavefront/no-watertight"]["git_revision"] = "5a7952c7a307-dirty"
    ctx = mitsuba_speed_history.bench_json(res, "2026-01-01T00:00:00+00:00")["context"]
    assert ctx["git_revision"] == "5a7952c7a307" and ctx["git_dirty"] is True


def test_a_render_timed_at_zero_is_named():
    res = _result()
    res["mitsuba"]["seconds"], res["pathbench"]["wavefront/no-watertight"]["seconds"] = [1.0, 2.0], [0.0, 0.1]
    assert mitsuba_speed.too_short(res) == ["pathbench wavefront/no-watertight"]


@pytest.mark.skipif(not EXE.exists(), reason="build/bin/pathbench not built")
def test_a_tiny_run_end_to_end(tmp_path):
    pytest.importorskip("mitsuba")
    db = tmp_path / "h.sqlite"
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "mitsuba_speed.py"), "--size", "48", "--spp", "64",
                        "--rounds", "2", "--mitsuba-per-round", "2", "--strategies", "wavefront", "--no-raw",
                        "--out-dir", str(tmp_path), "--history-db", str(db)], capture_output=True, text=True)
    if r.returncode != 0 and "libLLVM" in r.stderr + r.stdout:
        pytest.skip("Mitsuba's llvm variant needs libLLVM")
    assert r.returncode == 0, r.stderr
    res = json.loads((tmp_path / "mitsuba-vs-pathbench.json").read_text(), parse_constant=pytest.fail)
    m, p = res["mitsuba"], res["pathbench"]["wavefront"]
    assert len(m["runs"]) == 4 and [x["round"] for x in m["runs"]] == [0, 0, 1, 1]
    assert len(p["runs"]) == 2 and m["spread"]["n"] == 4
    assert all(x["load_before"]["cpu_count"] == os.cpu_count() and len(x["load_after"]["loadavg"]) == 3
               for x in m["runs"] + p["runs"])
    assert res["fingerprint"]["machine_id"] and res["settings"]["enough_repetitions"] is False
    assert len(p["speedup_by_round"]) == 2 and p["speedup_range"][0] <= p["speedup_range"][1]
    n = sqlite3.connect(db).execute("SELECT COUNT(*) FROM results WHERE benchmark LIKE 'mitsuba/cpu/%'").fetchone()
    assert n == (2,)
