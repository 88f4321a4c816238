"""`pathbench suite` (tools/suite): manifest validation, the quick suite end to end (strict
JSON, records in a database outside the tree, the page in headless Chromium). The render
report's energy figures: test_energy_report.py."""
import json
import re
import os
import shutil
import sqlite3
import subprocess
from pathlib import Path

import pytest

from suite import manifest, results

ROOT = Path(__file__).resolve().parents[2]
PATHBENCH = ROOT / "build" / "bin" / "pathbench"
BENCH = ROOT / "build" / "bin" / "pathbench-bench"
TEST_MANIFEST = ROOT / "tests" / "suite" / "manifest.json"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_build = pytest.mark.skipif(not (PATHBENCH.exists() and BENCH.exists()),
                                 reason="needs build/bin/pathbench and pathbench-bench (scripts/build.sh)")


def strict_load(path):
    def refuse(c):
        raise ValueError(f"{path}: {c}")
    return json.loads(Path(path).read_text(), parse_constant=refuse)


def suite(*args, env=None, cwd=None):
    e = dict(os.environ)
    e.update(env or {})
    return subprocess.run([str(PATHBENCH), "suite", *map(str, args)], capture_output=True, text=True, env=e,
                          cwd=cwd, timeout=900)


def write_manifest(tmp_path, workloads, **top):
    doc = {"suite": "pathbench", "version": 1, "workloads": workloads} | top
    p = tmp_path / "manifest.json"
    p.write_text(json.dumps(doc))
    return p


def good_workload(**kw):
    w = {"name": "box", "scene": "paper-cornell", "stresses": "s", "triangles": 14, "instanced_triangles": 0,
         "materials": ["diffuse"], "licence": "l", "settings": {"width": 8, "height": 8, "spp": 1},
         "quick": {"width": 8, "height": 8, "spp": 1}}
    w.update(kw)
    return w


@pytest.mark.parametrize("bad, field", [
    ({"settings": {"width": 8, "height": 8}}, "settings: 'spp' is missing"),
    ({"settings": {"width": 8, "height": 8, "spp": 1, "sampling": "magic"}}, "settings.sampling"),
    ({"settings": {"width": 8, "height": 8, "spp": 1, "lens": 3}}, "settings.lens: unknown setting"),
    ({"triangles": -1}, "triangles"),
    ({"name": "a b"}, "name"),
    ({"scene": "nowhere.json"}, "scene: nowhere.json: no such file"),
    ({"requires": [{"package": "p"}]}, "requires[0]"),
    ({"color": "red"}, "color: unknown field"),
])
def test_manifest_errors_name_the_file_and_field(tmp_path, bad, field):
    p = write_manifest(tmp_path, [good_workload(**bad)])
    with pytest.raises(manifest.ManifestError) as e:
        manifest.load(str(p))
    assert str(p) in str(e.value) and field in str(e.value)


def test_manifest_top_level_and_regex_errors(tmp_path):
    for text, what in [("{", "not valid JSON"), ('{"suite": "x", "version": 1, "workloads": []}', "suite"),
                       ('{"suite": "pathbench", "version": 0, "workloads": []}', "version"),
                       ('{"suite": "pathbench", "version": 1, "workloads": [1e999]}', "workloads[0]")]:
        p = tmp_path / "m.json"
        p.write_text(text)
        with pytest.raises(manifest.ManifestError, match=re.escape(what)):
            manifest.load(str(p))
    m = manifest.load(str(write_manifest(tmp_path, [good_workload(), good_workload(name="two")])))
    assert [w["name"] for w in manifest.select(m, "^t")] == ["two"]
    for pattern, what in [("(", "not a regular expression"), ("zzz", "matches no workload")]:
        with pytest.raises(manifest.ManifestError, match=what):
            manifest.select(m, pattern)
    dup = write_manifest(tmp_path, [good_workload(), good_workload()])
    with pytest.raises(manifest.ManifestError, match="appears twice"):
        manifest.load(str(dup))


def test_missing_or_empty_mesh_names_package_and_file(tmp_path):
    w = good_workload(requires=[{"package": "libcgal-demo", "file": "bunny00.off"}])
    m = manifest.load(str(write_manifest(tmp_path, [w])))
    why = manifest.missing_requirement(m["workloads"][0], str(tmp_path / "data"))
    assert "libcgal-demo" in why and "bunny00.off" in why
    (tmp_path / "data" / "meshes").mkdir(parents=True)
    (tmp_path / "data" / "meshes" / "bunny00.off").write_text("")
    assert "empty" in manifest.missing_requirement(m["workloads"][0], str(tmp_path / "data"))
    (tmp_path / "data" / "meshes" / "bunny00.off").write_text("OFF\n")
    assert manifest.missing_requirement(m["workloads"][0], str(tmp_path / "data")) is None


def test_u_test_verdicts_follow_compare():
    a = [10.0 + 0.01 * i for i in range(9)]
    assert results.verdict(a, a)["verdict"] == "same"
    assert results.verdict([x * 1.2 for x in a], a)["verdict"] == "slower"
    assert results.verdict([x * 0.8 for x in a], a)["verdict"] == "faster"
    assert results.verdict([x * 1.02 for x in a], a)["verdict"] == "same"  # under the 5 % threshold
    assert results.mann_whitney_p(a, [x + 100 for x in a]) < 1e-3


def test_reference_machines_name_a_gpu_runs_gpu(tmp_path):
    # Lent GPU hosts share one CPU model, so two GPUs' suite runs carry one machine name: the
    # page's reference column must not show an H100's times under the name an H200 run has too.
    def run(source, label, gpu, ms, bench):
        head = {"run": {"preset": "suite", "source": source, "machine_name": "intel-r-xeon-r", "commit": "c",
                        "run_date": "2026-11-27T00:56:29+00:00",
                        "context": {"suite_device_label": label, "gpu_name": gpu, "machine": "intel-r-xeon-r"}}}
        rows = [{"benchmark": bench, "unit": "ms", "value": v} for v in ms]
        (tmp_path / f"{source}.jsonl").write_text("\n".join(json.dumps(x) for x in [head, *rows]) + "\n")
    run("a-gpu.json", "gpu", "NVIDIA H100 80GB HBM3", [11.0, 12.0, 13.0], "suite/box/gpu/pixel/manual_time")
    run("a-cpu.json", "cpu", "NVIDIA H100 80GB HBM3", [500.0], "suite/box/cpu/pixel/manual_time")
    refs = results.reference_runs(str(tmp_path), "suite")
    assert set(refs) == {"intel-r-xeon-r", "intel-r-xeon-r · NVIDIA H100 80GB HBM3"}
    assert refs["intel-r-xeon-r · NVIDIA H100 80GB HBM3"]["suite/box/gpu/pixel"]["times_ms"] == [11.0, 12.0, 13.0]
    assert list(refs["intel-r-xeon-r"]) == ["suite/box/cpu/pixel"]


@needs_build
def test_bad_input_exits_2_with_one_line_and_writes_nothing(tmp_path):
    out = tmp_path / "page"
    bad = tmp_path / "bad.json"
    bad.write_text('{"suite": "pathbench", "version": 1, "workloads": [{"name": "x"}]}')
    for args, what in [(["--manifest", bad], "bad.json: workloads[0] (x).scene: missing"),
                       (["--manifest", TEST_MANIFEST, "--workloads", "("], "--workloads: not a regular expression"),
                       (["--manifest", TEST_MANIFEST, "--workloads", "nothing-matches"], "matches no workload"),
                       (["--manifest", TEST_MANIFEST, "--devices", "tpu"], "--devices: unknown device 'tpu'"),
                       (["--manifest", TEST_MANIFEST, "--bogus"], "unrecognized arguments")]:
        r = suite(*args, "--out", out, "--db", tmp_path / "h.sqlite")
        assert r.returncode == 2, (args, r.stderr)
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and what in lines[0], r.stderr
    assert not out.exists() and not (tmp_path / "h.sqlite").exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


@needs_build
def test_quick_suite_end_to_end(tmp_path):
    """The CI subset: built-in workloads at quick size on the CPU, 9 repetitions; twice, so the
    second page compares with the first run from the database."""
    data_home = tmp_path / "xdg"
    env = {"XDG_DATA_HOME": str(data_home), "PATHBENCH_DATA_DIR": str(tmp_path / "data")}
    out1, out2 = tmp_path / "run1", tmp_path / "run2"
    r = suite("--quick", "--manifest", TEST_MANIFEST, "--devices", "cpu", "--workloads", "paper-uniform|needs-mesh",
              "--out", out1, env=env)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "skipped needs-mesh" in r.stderr and "pathbench-test-no-such-package" in r.stderr
    db = data_home / "pathbench" / "history.sqlite"
    assert db.exists() and ROOT not in db.parents  # the default database, outside the tree
    r2 = suite("--quick", "--manifest", TEST_MANIFEST, "--devices", "cpu", "--workloads", "paper-uniform",
               "--out", out2, env=env)
    assert r2.returncode == 0, r2.stderr[-3000:]
    s = strict_load(out2 / "suite.json")
    bench = [strict_load(out2 / f) for f in s["bench_json"]]
    assert s["version"] == 1 and s["mode"] == "quick" and s["preset"] == "suite-quick"
    row = next(r for r in s["rows"] if r["workload"] == "paper-uniform")
    assert row["status"] == "ok" and row["repetitions"] == 9 and row["ms"] > 0 and row["rays_per_second"] > 0
    assert row["film_hash"].startswith("fnv1a64:") and row["peak_host_bytes"] > 0
    assert row["previous"]["verdict"] in ("same", "faster", "slower")  # against run 1, from the database
    # Energy: a number where RAPL is readable, else null with the reason (this VM: no powercap).
    if row["joules_per_frame"] is None:
        assert row["energy_reason"] and "powercap" in row["energy_reason"]
        assert "energy_unavailable" in bench[0]["context"]
    con = sqlite3.connect(db)
    presets = con.execute("SELECT preset, count(*) FROM runs GROUP BY preset").fetchall()
    n = con.execute("SELECT count(*) FROM results WHERE benchmark = 'suite/paper-uniform/cpu/pixel/manual_time'").fetchone()[0]
    con.close()
    assert presets == [("suite-quick", 2)] and n == 18
    s1 = strict_load(out1 / "suite.json")
    skipped = next(r for r in s1["rows"] if r["workload"] == "needs-mesh")
    assert skipped["status"] == "skipped" and "no-such-mesh.off" in skipped["reason"]
    md = (out2 / "suite.md").read_text()
    assert "paper-uniform" in md and "vs previous run" in md
    html = (out2 / "index.html").read_text()
    assert "paper-uniform" in html and "<script" not in html
    if CHROMIUM:
        r = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr",
                            "--v=0", f"--user-data-dir={tmp_path / 'profile'}", "--dump-dom",
                            (out2 / "index.html").as_uri()], capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr[-2000:]
        assert [l for l in r.stderr.splitlines() if ":CONSOLE" in l] == []
        assert "paper-uniform" in r.stdout and "vs previous run" in r.stdout


@needs_build
def test_compare_flags_a_throttled_run(tmp_path):
    def bench(path, ms, throttled):
        rows = [{"name": "render/gpu/pixel/x/manual_time", "run_name": "render/gpu/pixel/x/manual_time",
                 "run_type": "iteration", "repetition_index": i, "iterations": 10, "real_time": ms + 0.01 * i,
                 "cpu_time": ms, "time_unit": "ms", "throttled": float(throttled), "throttle_reasons": 4.0 * throttled}
                for i in range(9)]
        path.write_text(json.dumps({"context": {"date": "2026-11-26"}, "benchmarks": rows}))
        return path
    a, b = bench(tmp_path / "a.json", 10.0, 0), bench(tmp_path / "b.json", 10.0, 1)
    r = subprocess.run([str(PATHBENCH), "compare", str(a), str(b)], capture_output=True, text=True)
    assert "THROTTLED in new" in r.stdout, r.stdout + r.stderr
    r = subprocess.run([str(PATHBENCH), "compare", str(a), str(a)], capture_output=True, text=True)
    assert "THROTTLED" not in r.stdout


REAL_MANIFEST = ROOT / "scenes" / "suite" / "manifest.json"


@needs_build
@pytest.mark.skipif(not REAL_MANIFEST.exists(), reason="no scenes/suite/manifest.json")
def test_the_suites_manifest_loads_and_a_quick_subset_runs(tmp_path):
    """The real workloads: the manifest validates; a CI subset (the paper box, a scanned mesh
    where libcgal-demo's meshes are installed, the Mitsuba XML scene) runs at quick size."""
    m = manifest.load(str(REAL_MANIFEST))
    assert m["version"] == 1 and len(m["workloads"]) >= 5
    env = {"XDG_DATA_HOME": str(tmp_path / "xdg"), "PATHBENCH_DATA_DIR": manifest.data_dir()}
    r = suite("--quick", "--devices", "cpu", "--workloads", "^(paper-nee|bunny-armadillo|mitsuba-box)$",
              "--out", tmp_path / "out", env=env)
    assert r.returncode == 0, r.stderr[-3000:]
    s = strict_load(tmp_path / "out" / "suite.json")
    by = {row["workload"]: row for row in s["rows"]}
    assert set(by) == {"paper-nee", "bunny-armadillo", "mitsuba-box"}
    assert by["paper-nee"]["status"] == "ok" and by["mitsuba-box"]["status"] == "ok"
    if by["bunny-armadillo"]["status"] == "skipped":  # meshes not installed: the package is named
        assert "libcgal-demo" in by["bunny-armadillo"]["reason"]
    else:
        assert by["bunny-armadillo"]["triangles"] > 100_000


def test_a_truncated_mesh_is_named_by_its_checksum(tmp_path):
    data = tmp_path / "data"
    (data / "meshes").mkdir(parents=True)
    good = b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
    import hashlib
    w = good_workload(requires=[{"package": "libcgal-demo", "file": "tri.off", "sha256": hashlib.sha256(good).hexdigest()}])
    m = manifest.load(str(write_manifest(tmp_path, [w])))
    (data / "meshes" / "tri.off").write_bytes(good[:-8])  # cut short
    why = manifest.missing_requirement(m["workloads"][0], str(data))
    assert "tri.off" in why and "libcgal-demo" in why and "SHA-256" in why
    (data / "meshes" / "tri.off").write_bytes(good)
    assert manifest.missing_requirement(m["workloads"][0], str(data)) is None


@needs_build
def test_a_malformed_scene_skips_its_workload_and_the_rest_run(tmp_path):
    (tmp_path / "broken.json").write_text('{"camera": ')
    p = write_manifest(tmp_path, [good_workload(), good_workload(name="broken", scene="broken.json")])
    r = suite("--quick", "--manifest", p, "--devices", "cpu", "--repetitions", "2", "--no-record",
              "--out", tmp_path / "out")
    assert r.returncode == 0, r.stderr[-2000:]
    rows = {row["workload"]: row for row in strict_load(tmp_path / "out" / "suite.json")["rows"]}
    assert rows["box"]["status"] == "ok"
    assert rows["broken"]["status"] == "skipped" and "broken.json" in rows["broken"]["reason"]


@needs_build
def test_asking_for_a_gpu_where_there_is_none_is_bad_input(tmp_path):
    if "cuda: on" in subprocess.run([str(PATHBENCH), "--version"], capture_output=True, text=True).stdout:
        pytest.skip("this build has the CUDA tracer")
    r = suite("--manifest", TEST_MANIFEST, "--devices", "gpu", "--out", tmp_path / "out", "--no-record")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "--devices gpu" in r.stderr
    assert not (tmp_path / "out").exists()


@needs_build
def test_frames_on_a_scene_built_once_give_the_renders_image_and_fewer_repetitions_keep_names(tmp_path):
    """The suite's benchmarks build the scene once (run::BuiltScene) and time frames on it:
    the film hash is `pathbench render`'s for the same settings (which builds per call), every
    row carries build_seconds, and --repetitions-for runs those workloads in a pathbench-bench
    of their own, so their names stay the history's series (no /repeats:N)."""
    r = suite("--quick", "--manifest", TEST_MANIFEST, "--devices", "cpu", "--workloads", "^paper-(nee|uniform)$",
              "--repetitions-for", "uniform=2", "--no-record", "--out", tmp_path / "out")
    assert r.returncode == 0, r.stderr[-3000:]
    s = strict_load(tmp_path / "out" / "suite.json")
    by = {row["workload"]: row for row in s["rows"]}
    assert by["paper-nee"]["repetitions"] == 9 and by["paper-uniform"]["repetitions"] == 2
    assert len(s["bench_json"]) == 2  # one pathbench-bench per repetition count
    names = {b["name"] for f in s["bench_json"] for b in strict_load(tmp_path / "out" / f)["benchmarks"]}
    assert "suite/paper-uniform/cpu/pixel/manual_time" in names and not any("repeats" in n for n in names)
    for f in s["bench_json"]:
        rows = [b for b in strict_load(tmp_path / "out" / f)["benchmarks"] if b["run_type"] == "iteration"]
        assert rows and all(b["build_seconds"] > 0 for b in rows)
    assert "(n=2)" in (tmp_path / "out" / "suite.md").read_text()
    assert "paper-uniform 2" in dict(s["facts"])["repetitions"]
    for name, sampling in (("paper-nee", "nee"), ("paper-uniform", "uniform")):
        rep = tmp_path / f"{name}.json"
        args = ["--scene", "paper-cornell", "--device", "cpu", "--width", "32", "--height", "32", "--spp", "4",
                "--bounces", "2", "--sampling", sampling, "--report", str(rep)]
        rr = subprocess.run([str(PATHBENCH), "render", *args], capture_output=True, text=True, timeout=300)
        assert rr.returncode == 0, rr.stderr
        assert by[name]["film_hash"] == strict_load(rep)["film_hash"]


def mitsuba_available() -> bool:
    r = subprocess.run([str(ROOT / ".venv" / "bin" / "python"), "-c", "import mitsuba"], capture_output=True)
    return r.returncode == 0


@needs_build
def test_crosscheck_options_are_checked_before_anything_runs(tmp_path):
    out = tmp_path / "out"
    for args, what in [(["--crosscheck-size", "0x5"], "--crosscheck-size '0x5': expected WIDTHxHEIGHT"),
                       (["--crosscheck-size", "32"], "--crosscheck-size '32'"),
                       (["--mitsuba-variant", "../x"], "--mitsuba-variant '../x': not a Mitsuba variant"),
                       (["--crosscheck-spp", "0"], "--crosscheck-spp 0: must be 1 to"),
                       (["--crosscheck", "--from-json", tmp_path / "x.json"], "--crosscheck: measures nothing itself"),
                       (["--repetitions-for", "paper=0"], "--repetitions-for 'paper=0': expected REGEX=N"),
                       (["--repetitions-for", "(=3"], "not a regular expression")]:
        r = suite("--manifest", TEST_MANIFEST, *args, "--out", out, "--no-record")
        assert r.returncode == 2, (args, r.stderr)
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and what in lines[0], (args, r.stderr)
    assert not out.exists()
    if "cuda: on" not in subprocess.run([str(PATHBENCH), "--version"], capture_output=True, text=True).stdout:
        r = suite("--manifest", TEST_MANIFEST, "--crosscheck", "--devices", "gpu", "--out", out)
        assert r.returncode == 2 and "--devices gpu" in r.stderr and not out.exists()


@needs_build
@pytest.mark.skipif(not mitsuba_available(), reason="Mitsuba 3 not installed in .venv")
def test_crosscheck_mode_judges_each_workload_and_device_against_mitsuba(tmp_path):
    """--crosscheck: one verdict per (workload, device) with crosscheck's statistic, in
    crosscheck.json (strict) and crosscheck.md; exit 0 when every one passes. On the GPU host:
    --devices gpu --mitsuba-variant cuda_ad_rgb (results/suite/README.md)."""
    out = tmp_path / "cc"
    r = suite("--manifest", TEST_MANIFEST, "--crosscheck", "--devices", "cpu", "--workloads",
              "^(paper-nee|cornell-ggx)$", "--crosscheck-size", "24x24", "--crosscheck-spp", "64", "--out", out)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    doc = strict_load(out / "crosscheck.json")
    assert doc["mitsuba_variant"] == "scalar_rgb" and doc["frame"] == [24, 24] and doc["spp"] == 64
    rows = {row["workload"]: row for row in doc["rows"]}
    assert set(rows) == {"paper-nee", "cornell-ggx"}
    for row in rows.values():
        assert row["device"] == "cpu" and row["status"] == "pass" and row["values"] == 24 * 24 * 3
        assert row["share_passed"] >= 0.99 and all(abs(x - 1) <= 0.02 for x in row["mean_ratio"])
        assert row["mitsuba_spp"] == 256 and row["pathbench_spp"] == 64
    md = (out / "crosscheck.md").read_text()
    assert "| paper-nee | cpu | paper-cornell | pass |" in md and "scalar_rgb" in md
    assert "crosscheck: 2 of 2 pass" in r.stdout
