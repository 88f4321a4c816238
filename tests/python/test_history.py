"""The performance history (tools/history): recording, the text export and rebuild, machine
identity, change points on synthetic series built from a real bench JSON, and the CLI's exit codes."""
import json
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from history import changes, runfile, store, synthetic

ROOT = Path(__file__).resolve().parents[2]
QUICK = ROOT / "tests" / "data" / "bench" / "quick-9rep.json"


def hist(*args, check=None):
    env = os.environ | {"PYTHONPATH": str(ROOT / "tools")}
    r = subprocess.run([sys.executable, "-m", "history", *map(str, args)], capture_output=True, text=True, env=env)
    if check is not None:
        assert r.returncode == check, r.stdout + r.stderr
    return r


def rows(db, sql):
    con = sqlite3.connect(db)
    try:
        return con.execute(sql).fetchall()
    finally:
        con.close()


def test_record_stores_every_repetition_and_refuses_the_same_run(tmp_path):
    db, ex = tmp_path / "h.sqlite", tmp_path / "runs"
    r = hist("record", "--db", db, "--export", ex, QUICK, check=0)
    assert "144 rows" in r.stdout
    data = json.loads(QUICK.read_text(), parse_constant=lambda c: None)
    iterations = [b for b in data["benchmarks"] if b["run_type"] == "iteration"]
    assert rows(db, "SELECT COUNT(*) FROM results") == [(len(iterations),)]
    first = iterations[0]
    got = rows(db, f"SELECT value, unit, rays_per_second, counters FROM results WHERE benchmark='{first['run_name']}' "
                   "AND repetition=0")[0]
    assert got[0] == pytest.approx(first["real_time"]) and got[1] == first["time_unit"]
    assert got[2] == pytest.approx(first["rays_per_second"])
    assert json.loads(got[3])["peak_host_bytes"] == first["peak_host_bytes"]
    (commit, date, film_hash), = rows(db, "SELECT commit_sha, run_date, film_hash FROM runs")
    assert commit.startswith("f08fe19c9333")  # made the full hash where the clone has the commit
    assert (date, film_hash) == ("2026-11-22T15:28:07+00:00", None)
    r = hist("record", "--db", db, "--export", ex, QUICK, check=2)
    assert "already recorded" in r.stderr
    assert rows(db, "SELECT COUNT(*) FROM runs") == [(1,)] and len(list(ex.iterdir())) == 1


def test_commit_date_and_machine_options_override_the_json(tmp_path):
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", "--commit", "abc123", "--date", "2026-01-02T03:04:05Z",
         "--machine", "box", QUICK, check=0)
    assert rows(db, "SELECT commit_sha, run_date FROM runs") == [("abc123", "2026-01-02T03:04:05+00:00")]
    assert rows(db, "SELECT name FROM machines") == [("box",)]
    assert hist("record", "--db", db, "--date", "yesterday", QUICK).returncode == 2


def test_malformed_truncated_or_unknown_json_stores_nothing(tmp_path):
    db = tmp_path / "h.sqlite"
    truncated = tmp_path / "truncated.json"
    truncated.write_text(QUICK.read_text()[:5000])
    other = ROOT / "tests" / "data" / "bench" / "not-benchmark.json"
    for bad in (truncated, other, tmp_path / "missing.json"):
        r = hist("record", "--db", db, "--export", tmp_path / "runs", QUICK, bad, check=2)
        assert str(bad.name) in r.stderr and r.stderr.count("\n") == 1
    # One bad file among good ones: none of them stored, no text export left behind.
    assert not db.exists() or rows(db, "SELECT COUNT(*) FROM runs") == [(0,)]
    assert not (tmp_path / "runs").exists() or not list((tmp_path / "runs").iterdir())


def test_render_report_is_one_row_with_its_film_hash(tmp_path):
    report = {"device": "cpu", "strategy": "pixel", "scene": "paper-cornell", "width": 64, "height": 64, "spp": 16,
              "bounces": 2, "sampling": "nee", "seconds": 0.072, "rays_per_second": 3.27e6, "git_revision": "ffccb95e8b01",
              "machine": {"cpu": "AMD EPYC", "hardware_threads": 2, "threads": 1}, "rays": {"total": 235618},
              "film_hash": "sha256:00ff"}
    p = tmp_path / "report.json"
    p.write_text(json.dumps(report))
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", "--date", "2026-11-23T00:00:00Z", p, check=0)
    assert rows(db, "SELECT benchmark, value, unit, rays_per_second FROM results") == [
        ("render/cpu/pixel/paper-cornell/64x64/spp:16/bounces:2/nee", pytest.approx(72.0), "ms", 3.27e6)]
    assert rows(db, "SELECT kind, film_hash FROM runs") == [("render", "sha256:00ff")]


def test_text_export_rebuilds_the_same_database(tmp_path):
    db, ex = tmp_path / "h.sqlite", tmp_path / "runs"
    paths = synthetic.write_history(QUICK, tmp_path / "json", 3, 0.02, seed=3)
    hist("record", "--db", db, "--export", ex, *paths, check=0)
    files = sorted(ex.iterdir())
    assert len(files) == 3 and files == sorted(files, key=lambda f: f.name)  # time order by name
    hist("rebuild", "--db", tmp_path / "again.sqlite", "--export", ex, check=0)
    q = "SELECT u.commit_sha, r.benchmark, r.repetition, r.value, r.counters FROM results r JOIN runs u ON u.id=r.run_id " \
        "ORDER BY 1, 2, 3"
    assert rows(db, q) == rows(tmp_path / "again.sqlite", q) and len(rows(db, q)) == 3 * 144
    # The export is stable: writing a run again gives the same bytes.
    run = runfile.read_run(str(files[0]))
    again = runfile.write_run(str(tmp_path / "copy"), run)
    assert Path(again).read_bytes() == files[0].read_bytes()


def test_machine_id_from_fingerprint_ignores_volatile_keys_and_falls_back_to_context():
    fp = {"cpu": {"model": "AMD EPYC 9654", "l2_bytes": 1048576}, "load": [0.1, 0.2, 0.3], "date": "2026-01-01"}
    a = store.machine_id({"fingerprint": fp, "host_name": "x"})
    b = store.machine_id({"fingerprint": fp | {"load": [3, 3, 3], "date": "2027-01-01"}, "host_name": "y"})
    c = store.machine_id({"fingerprint": fp | {"cpu": {"model": "AMD EPYC 9654", "l2_bytes": 524288}}})
    assert a == b and a != c
    ctx = json.loads(QUICK.read_text(), parse_constant=lambda c: None)["context"]
    d = store.machine_id(ctx)
    assert d == store.machine_id(ctx | {"load_avg": [9, 9, 9], "date": "2030-01-01T00:00:00Z"})
    assert d != store.machine_id(ctx | {"mhz_per_cpu": 2596})  # the two "amd-epyc" hosts
    assert store.machine_description(ctx) == {k: ctx[k] for k in store.FALLBACK_KEYS}
    with pytest.raises(ValueError):
        store.machine_id({"date": "2026-01-01"})


def test_changes_names_the_stepped_commit_and_nothing_else(tmp_path):
    """Acceptance: 30 runs from quick-9rep.json, 2% run noise + 1% per repetition, +10% at run 17 on
    the render benchmarks (slower) only: `changes --json` names commit 17 (+-1) for each of them and
    reports nothing for the raycast ones."""
    step_at = 17
    stepped = lambda name: name.startswith("render/")  # noqa: E731
    paths = synthetic.write_history(QUICK, tmp_path / "json", 30, 0.02, seed=11, step_at=step_at, stepped=stepped)
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", *paths, check=0)
    found = json.loads(hist("changes", "--db", db, "--json", check=0).stdout)
    names = {b for (b,) in rows(db, "SELECT DISTINCT benchmark FROM results")}
    render = {n for n in names if stepped(n)}
    assert len(render) == 4 and len(names) == 16
    assert {c["benchmark"] for c in found} == render
    near = {synthetic.fake_commit(i, "synthetic-host") for i in (step_at - 1, step_at, step_at + 1)}
    for c in found:
        assert set(c) >= {"benchmark", "machine", "commit", "previous_commit", "change", "p_value"}
        assert c["commit"] in near and c["change"] == pytest.approx(0.10, abs=0.04) and c["p_value"] < 1e-4
    # The newest run sits after a regression: exit 1, the regression named on stderr.
    r = hist("changes", "--db", db, "--benchmark", "^render/cpu/pixel", "--fail-on-regression", check=1)
    assert r.stderr.count("regression:") == 2
    assert hist("changes", "--db", db, "--benchmark", "^raycast", "--fail-on-regression", check=0).stdout.strip() \
        == "no change points"


def test_an_improvement_is_not_a_regression(tmp_path):
    paths = synthetic.write_history(QUICK, tmp_path / "json", 24, 0.02, seed=5, step_at=12, step=-0.12,
                                    stepped=lambda n: "wavefront" in n)
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", *paths, check=0)
    found = json.loads(hist("changes", "--db", db, "--json", "--fail-on-regression", check=0).stdout)
    assert found and all(c["change"] < 0 and not c["regression"] for c in found)


def test_flat_series_and_cli_errors(tmp_path):
    assert changes.detect([5.0] * 30) == []
    assert changes.detect([5.0] * 15 + [4.0] * 15) == [(15, pytest.approx(-0.2), 0.0)]
    assert hist("changes", "--db", tmp_path / "none.sqlite").returncode == 2
    bad = tmp_path / "bad.sqlite"
    sqlite3.connect(bad).execute("CREATE TABLE x (y)").connection.commit()
    r = hist("changes", "--db", bad)
    assert r.returncode == 2 and "not a pathbench history database" in r.stderr
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", QUICK, check=0)
    assert "regular expression" in hist("changes", "--db", db, "--benchmark", "(", check=2).stderr


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/install-deps.sh installs it)")
def test_dashboard_draws_in_headless_chromium_without_console_errors(tmp_path):
    paths = synthetic.write_history(QUICK, tmp_path / "json", 20, 0.03, seed=2, step_at=10,
                                    stepped=lambda n: n.startswith("render/cpu/pixel"))
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", *paths, check=0)
    site = tmp_path / "site"
    hist("report", "--db", db, "--out", site, check=0)
    pngs = list((site / "png").glob("*.png"))
    assert pngs and pngs[0].read_bytes()[:4] == b"\x89PNG"
    r = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr", "--v=0",
                        f"--user-data-dir={tmp_path / 'profile'}", "--virtual-time-budget=10000", "--dump-dom",
                        (site / "index.html").as_uri()], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    console = [line for line in r.stderr.splitlines() if ":CONSOLE" in line]
    assert console == []  # the page logs nothing; an uncaught exception would show here
    dom = r.stdout
    # 16 series, each a time chart and (all carry rays/s) a rays/s chart, each with its median line.
    assert 'data-drawn="32"' in dom
    assert dom.count('class="median"') == 32 and dom.count('class="rep"') >= 16 * 20 * 9
    assert dom.count('class="cp slower"') == 2 * 2  # two stepped series, marked on both of their charts


PATHBENCH = ROOT / "build" / "bin" / "pathbench"


@pytest.mark.skipif(not PATHBENCH.exists(), reason="build/bin/pathbench not built (scripts/build.sh)")
def test_pathbench_history_hands_over_and_passes_the_exit_status(tmp_path):
    env = os.environ | {"PATHBENCH_PYTHON": sys.executable}
    r = subprocess.run([PATHBENCH, "history", "record", "--db", tmp_path / "h.sqlite", "--export", "", QUICK],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0 and "144 rows" in r.stdout
    r = subprocess.run([PATHBENCH, "history", "record", "--db", tmp_path / "h.sqlite", "--export", "", QUICK],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 2 and "already recorded" in r.stderr
    r = subprocess.run([PATHBENCH, "history", "changes", "--db", tmp_path / "h.sqlite", "--json"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0 and json.loads(r.stdout) == []
    assert "history" in subprocess.run([PATHBENCH, "--help"], capture_output=True, text=True).stdout


@pytest.mark.skipif(not PATHBENCH.exists() or shutil.which("valgrind") is None,
                    reason="needs build/bin/pathbench and valgrind (scripts/install-deps.sh)")
def test_instruction_count_preset_is_a_bench_json_history_records(tmp_path):
    """Four callgrind runs of an 8x8, 1 spp render (about 40 s of CPU in all, mostly valgrind start-up)."""
    from history import instructions
    data = instructions.measure(str(PATHBENCH), wall_reps=1, revision="0" * 40, width=8, spp=1)
    names = {b["name"] for b in data["benchmarks"]}
    for s in ("pixel", "wavefront"):
        assert f"callgrind/paper-cornell/{s}/default/instructions" in names
        assert f"wall/paper-cornell/{s}/triangles/128x128/spp:16" in names
    counted = [b for b in data["benchmarks"] if b["time_unit"] == "instructions"]
    # Instructions per sample of a 64-sample render: thousands (startup and the BVH build are outside).
    assert all(1000 < b["real_time"] < 100000 and b["instructions"] == b["real_time"] * 64 for b in counted)
    p = tmp_path / "instr.json"
    p.write_text(json.dumps(data))
    hist("record", "--db", tmp_path / "h.sqlite", "--export", "", p, check=0)


def _git_repo(path):
    env = os.environ | {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
                        "GIT_COMMITTER_EMAIL": "t@t"}
    path.mkdir()
    subprocess.run(["git", "init", "-q", path], check=True)

    def commit(files: dict, msg: str):
        for name, body in files.items():
            (path / name).write_text(body)
        subprocess.run(["git", "-C", path, "add", "-A"], check=True)
        subprocess.run(["git", "-C", path, "commit", "-qm", msg], check=True, env=env)
    return commit


def test_backfill_git_results_records_every_committed_version(tmp_path):
    commit = _git_repo(tmp_path / "repo")
    paths = synthetic.write_history(QUICK, tmp_path / "json", 3, 0.02, seed=4)
    for i, p in enumerate(paths):
        commit({"bench-quick.json": Path(p).read_text()}, f"results {i}")
    db = tmp_path / "h.sqlite"
    r = hist("backfill", "--repo", tmp_path / "repo", "--db", db, "--export", "", "--git-results",
             tmp_path / "repo" / "bench-quick.json", check=0)
    assert r.stdout.count("recorded") == 3
    assert rows(db, "SELECT commit_sha FROM runs ORDER BY id") == [(synthetic.fake_commit(i, "synthetic-host"),)
                                                                   for i in range(3)]


@pytest.mark.skipif(shutil.which("cmake") is None or shutil.which("ninja") is None, reason="needs cmake and ninja")
def test_backfill_goes_on_past_commits_that_do_not_build_or_measure(tmp_path):
    """Two commits: one whose CMakeLists is broken, one that 'builds' a pathbench that is not one.
    Both are reported as failed and the backfill finishes (exit 0)."""
    commit = _git_repo(tmp_path / "repo")
    commit({"CMakeLists.txt": "this is not cmake(\n"}, "broken")
    commit({"CMakeLists.txt": "cmake_minimum_required(VERSION 3.20)\nproject(fake NONE)\n"
            "add_custom_target(pathbench ALL COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/bin\n"
            "  COMMAND ${CMAKE_COMMAND} -E copy ${CMAKE_SOURCE_DIR}/fake.sh ${CMAKE_BINARY_DIR}/bin/pathbench)\n",
            "fake.sh": "#!/bin/sh\necho not pathbench\n"}, "fake")
    os.chmod(tmp_path / "repo" / "fake.sh", 0o755)
    subprocess.run(["git", "-C", tmp_path / "repo", "update-index", "--chmod=+x", "fake.sh"], check=True)
    r = hist("backfill", "--repo", tmp_path / "repo", "--scratch", tmp_path / "scratch", "--json-dir",
             tmp_path / "out", "--wall", "0", "HEAD", check=0)
    assert "build failed" in r.stdout
    assert "measuring failed" in r.stdout or "build failed" in r.stdout.split("[2/2]")[1]
    assert "0 of 2 commits measured, 2 failed" in r.stdout
    r = hist("backfill", "--repo", tmp_path / "repo", "--scratch", tmp_path / "scratch", "no-such-rev..HEAD", check=2)
    assert "not a revision range" in r.stderr


def test_instruction_counts_report_every_exact_step(tmp_path):
    """Noise-free counts: a staircase of consecutive improvements is reported step by step (Otava
    would merge it), a 0.2% wobble is not, and the newest run after a +3% step fails the gate."""
    values = [5000.0] * 5 + [4300.0, 4000.0, 3900.0] + [3890.0] * 5 + [3900.0] * 3 + [4017.0] * 2
    paths = []
    for i, v in enumerate(values):
        data = {"context": {"host_name": "h", "cpu_model": "c", "num_cpus": 2, "git_revision": f"{i:040x}",
                            "date": f"2026-01-01T00:{i:02d}:00Z", "pathbench_preset": "instructions"},
                "benchmarks": [{"name": "callgrind/x/instructions", "run_type": "iteration", "repetition_index": 0,
                                "real_time": v, "cpu_time": v, "time_unit": "instructions", "iterations": 1}]}
        paths.append(tmp_path / f"{i}.json")
        paths[-1].write_text(json.dumps(data))
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", *paths, check=0)
    r = hist("changes", "--db", db, "--json", "--fail-on-regression", check=1)
    found = json.loads(r.stdout)
    assert [(c["commit"], round(c["change"], 3), c["method"], c["p_value"]) for c in found] == [
        (f"{5:040x}", -0.14, "exact", None), (f"{6:040x}", -0.07, "exact", None),
        (f"{7:040x}", -0.025, "exact", None), (f"{16:040x}", 0.03, "exact", None)]
    assert "regression: callgrind/x/instructions" in r.stderr
    otava = json.loads(hist("changes", "--db", db, "--json", "--otava-only", check=0).stdout)
    assert otava and all(c["method"] == "otava" for c in otava)


PATHBENCH = ROOT / "build" / "bin" / "pathbench"


@pytest.mark.skipif(not PATHBENCH.exists(), reason="needs build/bin/pathbench")
def test_real_render_reports_record_their_film_hash(tmp_path):
    """Speed and correctness in one row: two real renders of one image (pixel and
    wavefront, bit-identical films) record one film hash; another spp another."""
    db = tmp_path / "h.sqlite"
    hashes = {}
    for i, (strategy, spp) in enumerate((("pixel", 2), ("wavefront", 2), ("pixel", 3))):
        report = tmp_path / f"r{i}.json"
        subprocess.run([str(PATHBENCH), "render", "--scene", "paper-cornell", "--width", "16", "--height", "16",
                        "--spp", str(spp), "--strategy", strategy, "--quiet", "--report", str(report)], check=True)
        hashes[i] = json.loads(report.read_text())["film_hash"]
        hist("record", "--db", db, "--export", "", "--commit", f"{i:040x}", report, check=0)
    stored = [h for (h,) in rows(db, "SELECT film_hash FROM runs ORDER BY id")]
    assert stored == [hashes[0], hashes[1], hashes[2]]
    assert hashes[0] == hashes[1] != hashes[2] and hashes[0].startswith("fnv1a64:")
