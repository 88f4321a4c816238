"""`pathbench history` on hostile input (issue 34): every bad database, path and field ends in exit 2
with one message line and no traceback, nothing stored and nothing left behind; 3 only for a bug;
concurrent writers lose nothing; git never sees a revision as an option; no name reaches the
terminal, a Markdown table or the dashboard raw. Each test failed on main at 45d2ef6."""
import copy
import json
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
QUICK = ROOT / "tests" / "data" / "bench" / "quick-9rep.json"
BASE = json.loads(QUICK.read_text(), parse_constant=lambda c: None)
# PATHBENCH_HISTORY_TOOLS: run these tests against another tree's tools/ (to see them fail before a fix).
TOOLS = os.environ.get("PATHBENCH_HISTORY_TOOLS", str(ROOT / "tools"))


def hist(*args, check=None, cwd=None, timeout=120):
    env = os.environ | {"PYTHONPATH": TOOLS}
    env.pop("PATHBENCH_DEBUG", None)
    r = subprocess.run([sys.executable, "-m", "history", *map(str, args)], capture_output=True, text=True, env=env,
                       cwd=cwd, timeout=timeout, errors="surrogateescape")
    if check is not None:
        assert r.returncode == check, r.stdout + r.stderr
    return r


def one_line_error(r, status=2):
    assert r.returncode == status, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    assert r.stderr.count("\n") == 1 and r.stderr.startswith("pathbench history: "), r.stderr
    return r.stderr


def count(db, sql="SELECT COUNT(*) FROM runs"):
    con = sqlite3.connect(db)
    try:
        return con.execute(sql).fetchall()[0][0]
    finally:
        con.close()


def leftovers(*folders):
    """Files a failed command must not leave: pending or temporary exports, rebuild databases, journals."""
    out = []
    for folder in folders:
        if Path(folder).is_dir():
            out += [p.name for p in Path(folder).rglob("*") if p.name.startswith(".") or "pending" in p.name
                    or "rebuild" in p.name or p.name.endswith(("-journal", "-wal", ".tmp"))]
    return out


def bench(path, mutate=None, **context):
    data = copy.deepcopy(BASE)
    data["context"].update(context)
    if mutate:
        mutate(data)
    Path(path).write_text(json.dumps(data) if not isinstance(data, bytes) else data)
    return path


def record_db(tmp_path):
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", QUICK, check=0)
    return db


# ---- databases and paths ----------------------------------------------------------------------------

def _corrupt(tmp_path):
    p = tmp_path / "corrupt.sqlite"
    p.write_bytes(b"SQLite format 3\0" + bytes(range(256)) * 40)
    return p


def _truncated(tmp_path):
    db = record_db(tmp_path)
    p = tmp_path / "truncated.sqlite"
    p.write_bytes(db.read_bytes()[:6000])
    return p


def _foreign(tmp_path):
    p = tmp_path / "foreign.sqlite"
    con = sqlite3.connect(p)
    con.execute("CREATE TABLE x (y)")
    con.commit()
    con.close()
    return p


def _text_file(tmp_path):
    p = tmp_path / "notes.txt"
    p.write_text("not a database\n" * 100)
    return p


def _folder(tmp_path):
    (tmp_path / "adir").mkdir()
    return tmp_path / "adir"


def _under_a_file(tmp_path):
    (tmp_path / "afile").write_text("x")
    return tmp_path / "afile" / "h.sqlite"


def edited_db(tmp_path, sql):
    db = record_db(tmp_path)
    con = sqlite3.connect(db)
    con.execute(sql)
    con.commit()
    con.close()
    return db


def _newer_schema(tmp_path):
    return edited_db(tmp_path, "UPDATE meta SET value='99' WHERE key='schema_version'")


BAD_DBS = [_corrupt, _truncated, _foreign, _text_file, _folder, _under_a_file, _newer_schema]


@pytest.mark.parametrize("make", BAD_DBS, ids=lambda f: f.__name__.strip("_"))
@pytest.mark.parametrize("cmd", ["record", "changes", "report", "rebuild"])
def test_a_bad_database_is_one_line_and_exit_2(tmp_path, make, cmd):
    db = make(tmp_path)
    before = db.read_bytes() if db.is_file() else None
    ex = tmp_path / "runs"
    if cmd == "record":
        r = hist("record", "--db", db, "--export", ex, QUICK)
    elif cmd == "changes":
        r = hist("changes", "--db", db)
    elif cmd == "report":
        r = hist("report", "--db", db, "--out", tmp_path / "site", "--no-png")
    else:
        ex.mkdir()
        r = hist("rebuild", "--db", db, "--runs", ex)  # never replaces what is not a history database
    msg = one_line_error(r)
    assert str(db.name) in msg or "adir" in msg or "afile" in msg
    if before is not None:
        assert db.read_bytes() == before  # a database we refuse is not touched
    assert not (ex.exists() and list(ex.iterdir())) and leftovers(tmp_path) == []
    assert not (tmp_path / "site").exists()


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes read-only files")
def test_a_read_only_database_is_refused_for_record_and_read_for_the_rest(tmp_path):
    db = record_db(tmp_path)
    os.chmod(db, 0o444)
    one_line_error(hist("record", "--db", db, "--export", "", bench(tmp_path / "b.json", git_revision="abc")))
    hist("changes", "--db", db, check=0)


def test_read_commands_never_write_the_database(tmp_path):
    db = record_db(tmp_path)
    before = db.read_bytes()
    hist("changes", "--db", db, check=0)
    hist("report", "--db", db, "--out", tmp_path / "site", "--no-png", check=0)
    assert db.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["h.sqlite", "site"]


def test_export_or_output_path_that_is_a_file(tmp_path):
    (tmp_path / "file").write_text("x")
    one_line_error(hist("record", "--db", tmp_path / "h.sqlite", "--export", tmp_path / "file", QUICK))
    assert not (tmp_path / "h.sqlite").exists() or count(tmp_path / "h.sqlite") == 0
    (tmp_path / "a").mkdir()
    db = record_db(tmp_path / "a")
    one_line_error(hist("report", "--db", db, "--out", tmp_path / "file", "--no-png"))
    one_line_error(hist("rebuild", "--db", tmp_path / "x.sqlite", "--runs", tmp_path / "file"))
    assert (tmp_path / "file").read_text() == "x" and leftovers(tmp_path) == []


# ---- fields of a bench JSON -------------------------------------------------------------------------

def _row(key, value):
    def mutate(d):
        d["benchmarks"][0][key] = value
    return mutate


def _ctx(key, value):
    def mutate(d):
        d["context"][key] = value
    return mutate


BAD_FIELDS = {
    "revision-list": _ctx("git_revision", ["f08fe19c9333"]),
    "revision-number": _ctx("git_revision", 12345),
    "revision-control": _ctx("git_revision", "abc\x1b[2Jdef"),
    "date-list": _ctx("date", ["2026-01-01"]),
    "date-past-9999": _ctx("date", "9999-12-31T23:00:00-05:00"),
    "date-year-10000": _ctx("date", "10000-01-01T00:00:00Z"),
    "date-before-1": _ctx("date", "0001-01-01T00:00:00+05:00"),
    "commit-date-past-9999": _ctx("commit_date", "9999-12-31T23:59:59-01:00"),
    "commit-seq-2^63": _ctx("commit_seq", 2 ** 63),
    "commit-seq-string": _ctx("commit_seq", "12"),
    "preset-list": _ctx("pathbench_preset", ["quick"]),
    "film-hash-object": _ctx("film_hash", {"a": 1}),
    "context-list": lambda d: d.update(context=[1, 2]),
    "benchmarks-object": lambda d: d.update(benchmarks={"a": 1}),
    "name-list": _row("name", ["a"]),
    "run-name-list": _row("run_name", ["a", "b"]),
    "run-name-number": _row("run_name", 7),
    "time-unit-list": _row("time_unit", ["ms"]),
    "real-time-string": _row("real_time", "3.5"),
    "real-time-bool": _row("real_time", True),
    "real-time-negative": _row("real_time", -1.0),
    "real-time-inf": _row("real_time", 1e999),
    "real-time-huge-int": _row("real_time", 10 ** 400),
    "iterations-2^63": _row("iterations", 2 ** 63),
    "iterations-2^64": _row("iterations", 2 ** 64),
    "iterations-list": _row("iterations", [1]),
    "repetition-2^63": _row("repetition_index", 2 ** 63),
    "repetition-negative": _row("repetition_index", -1),
    "repetition-list": _row("repetition_index", [0]),
    "repetition-string": _row("repetition_index", "0"),
}


@pytest.mark.parametrize("case", sorted(BAD_FIELDS))
def test_a_malformed_field_is_one_line_exit_2_and_stores_nothing(tmp_path, case):
    db, ex = tmp_path / "h.sqlite", tmp_path / "runs"
    p = tmp_path / "run.json"
    data = copy.deepcopy(BASE)
    BAD_FIELDS[case](data)
    text = json.dumps(data).replace("Infinity", "1e999")  # json.dumps writes inf as Infinity
    p.write_text(text)
    msg = one_line_error(hist("record", "--db", db, "--export", ex, QUICK, p))
    assert "run.json" in msg and "\x1b" not in msg
    assert not db.exists() or count(db) == 0
    assert not ex.exists() or list(ex.iterdir()) == []


@pytest.mark.parametrize("body, expect", [
    (b"\xff\xfe{\x00\x00\x00garbage", "not"),
    (b'{"context": {"git_revision": "\xc3\x28"}, "benchmarks": []}', "UTF-8"),
    (b'{"context": {"git_revision": "abc", "host_name": "\\ud800"}, "benchmarks": []}', "surrogate"),
    (b"[" * 100000 + b"]" * 100000, "nested too deeply"),
    (b'{"a":' * 70 + b"1" + b"}" * 70, "nested too deeply"),
    (b'{"context": {}, "benchmarks": [{"name": "x", "real_time": 1' + b"0" * 5000 + b', "time_unit": "ms"}]}',
     "not valid JSON"),
    (b"", "not valid JSON"),
], ids=["utf16-garbage", "not-utf8", "lone-surrogate", "deep-array", "deep-object", "5000-digit-int", "empty"])
def test_undecodable_or_deep_json_is_exit_2(tmp_path, body, expect):
    p = tmp_path / "run.json"
    p.write_bytes(body)
    msg = one_line_error(hist("record", "--db", tmp_path / "h.sqlite", "--export", tmp_path / "runs", p))
    assert expect in msg


def test_extremes_that_are_no_measurement_are_stored_as_null(tmp_path):
    """1e999 in a counter or cpu_time is no measurement: stored as null like NaN, the run kept."""
    p = bench(tmp_path / "b.json", lambda d: d["benchmarks"][0].update(cpu_time=1e999, peak_host_bytes=-1e999,
                                                                        big_counter=2 ** 70))
    p.write_text(p.read_text().replace("Infinity", "1e999"))
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", tmp_path / "runs", p, check=0)
    con = sqlite3.connect(db)
    cpu, counters = con.execute("SELECT cpu_time, counters FROM results ORDER BY rowid LIMIT 1").fetchone()
    assert cpu is None and json.loads(counters).get("peak_host_bytes") is None
    assert json.loads(counters)["big_counter"] == pytest.approx(2.0 ** 70)
    hist("rebuild", "--db", tmp_path / "again.sqlite", "--runs", tmp_path / "runs", check=0)


def test_a_huge_file_is_refused_with_the_limit_named(tmp_path):
    p = tmp_path / "huge.json"
    with open(p, "wb") as f:
        f.truncate((32 << 20) + 1)  # sparse: no disk used
    msg = one_line_error(hist("record", "--db", tmp_path / "h.sqlite", p))
    assert "larger than 32 MiB" in msg


def test_render_report_with_a_list_for_a_name_or_a_huge_size(tmp_path):
    report = {"device": "cpu", "strategy": ["pixel"], "scene": "x", "width": 8, "height": 8, "spp": 1, "bounces": 2,
              "sampling": "nee", "seconds": 0.1, "git_revision": "abc", "machine": {"cpu": "c"}}
    p = tmp_path / "r.json"
    p.write_text(json.dumps(report))
    assert "strategy" in one_line_error(hist("record", "--db", tmp_path / "h.sqlite", "--date", "2026-01-01", p))
    p.write_text(json.dumps(report | {"strategy": "pixel", "width": 2 ** 64}))
    assert "width" in one_line_error(hist("record", "--db", tmp_path / "h.sqlite", "--date", "2026-01-01", p))
    p.write_text(json.dumps(report | {"strategy": "pixel", "seconds": -0.5}))
    assert "negative" in one_line_error(hist("record", "--db", tmp_path / "h.sqlite", "--date", "2026-01-01", p))


# ---- record and rebuild: all or nothing, no leftovers ------------------------------------------------

def test_record_is_all_or_nothing_and_skip_recorded_skips(tmp_path):
    db, ex = tmp_path / "h.sqlite", tmp_path / "runs"
    other = bench(tmp_path / "other.json", git_revision="0" * 40)
    hist("record", "--db", db, "--export", ex, QUICK, check=0)
    msg = one_line_error(hist("record", "--db", db, "--export", ex, other, QUICK))
    assert "already recorded" in msg
    assert count(db) == 1 and len(list(ex.iterdir())) == 1  # other.json was not stored either
    r = hist("record", "--db", db, "--export", ex, "--skip-recorded", other, QUICK, check=0)
    assert "already recorded" in r.stdout and count(db) == 2 and len(list(ex.iterdir())) == 2


def test_rebuild_refuses_duplicate_run_files_and_keeps_the_old_database(tmp_path):
    db, ex = tmp_path / "h.sqlite", tmp_path / "runs"
    hist("record", "--db", db, "--export", ex, QUICK, check=0)
    (f,) = ex.iterdir()
    shutil.copy(f, ex / ("copy-" + f.name))
    before = db.read_bytes()
    msg = one_line_error(hist("rebuild", "--db", db, "--runs", ex))
    assert "the same run as" in msg
    assert db.read_bytes() == before and leftovers(tmp_path) == []


@pytest.mark.parametrize("damage", [
    lambda t: t.replace('"repetition":0', '"repetition":9223372036854775808', 1),
    lambda t: t.replace('"run_date":"', '"run_date":"99999-', 1),
    lambda t: t.replace('"commit":"', '"commit":"--output=x', 1),
    lambda t: t.replace('"unit":"ms"', '"unit":["ms"]', 1),
    lambda t: t.replace('"value":', '"value":"', 1),
    lambda t: t.split("\n", 1)[1],
    lambda t: t[: len(t) // 2],
    lambda t: "\udcff" + t,
], ids=["rep-2^63", "year-99999", "commit-option", "unit-list", "value-string", "no-header", "truncated", "not-utf8"])
def test_rebuild_of_a_damaged_run_file_is_exit_2_and_leaves_nothing(tmp_path, damage):
    db, ex = tmp_path / "h.sqlite", tmp_path / "runs"
    hist("record", "--db", db, "--export", ex, QUICK, check=0)
    (f,) = ex.iterdir()
    f.write_bytes(damage(f.read_text()).encode("utf-8", "surrogateescape"))
    before = db.read_bytes()
    msg = one_line_error(hist("rebuild", "--db", db, "--runs", ex))
    assert f.name in msg
    assert db.read_bytes() == before and leftovers(tmp_path) == [] and not (tmp_path / "x").exists()


def test_rebuild_reads_the_project_export_not_runs_beside_the_database(tmp_path):
    """issue 29: `history rebuild --db /tmp/h.sqlite` rebuilds from results/history/runs."""
    (tmp_path / "runs").mkdir()  # the folder beside the database, empty: not the one to read
    db = tmp_path / "h.sqlite"
    r = hist("rebuild", "--db", db, check=0, cwd=tmp_path)
    files = list((ROOT / "results" / "history" / "runs").glob("*.jsonl"))
    assert files and count(db) == len(files)
    assert str(ROOT / "results" / "history" / "runs") in r.stdout


def _large_run(path, i, rows=4000):
    data = {"context": {"host_name": "concurrency", "cpu_model": "c", "num_cpus": 2, "git_revision": f"{i:040x}",
                        "date": f"2026-01-01T00:{i:02d}:00Z", "commit_date": f"2026-01-01T00:{i:02d}:00Z"},
            "benchmarks": [{"name": f"bm/{k // 4}", "run_name": f"bm/{k // 4}", "run_type": "iteration",
                            "repetition_index": k % 4, "real_time": 1.0 + k, "cpu_time": 1.0, "time_unit": "ms",
                            "iterations": 10, "counter_a": k, "counter_b": 0.5} for k in range(rows)]}
    Path(path).write_text(json.dumps(data))
    return path


def test_ten_concurrent_records_of_large_runs_lose_nothing(tmp_path):
    """Ten processes record a 4,000-row run each into one new database at once: all ten stored
    (on main they raced creating the schema and lost runs to "database is locked")."""
    db, ex = tmp_path / "h.sqlite", tmp_path / "runs"
    paths = [_large_run(tmp_path / f"run{i}.json", i) for i in range(10)]
    env = os.environ | {"PYTHONPATH": TOOLS}
    procs = [subprocess.Popen([sys.executable, "-m", "history", "record", "--db", str(db), "--export", str(ex), str(p)],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env) for p in paths]
    results = [(p.wait(timeout=600), p.stderr.read()) for p in procs]
    for p in procs:
        p.stdout.close()
        p.stderr.close()
    assert [rc for rc, _ in results] == [0] * 10, results
    assert count(db) == 10 and count(db, "SELECT COUNT(*) FROM results") == 40000
    assert len(list(ex.glob("*.jsonl"))) == 10 and leftovers(tmp_path) == []


def test_a_signal_mid_record_leaves_nothing_behind(tmp_path):
    db, ex = tmp_path / "h.sqlite", tmp_path / "runs"
    p = _large_run(tmp_path / "big.json", 1, rows=60000)
    env = os.environ | {"PYTHONPATH": TOOLS}
    for delay in (0.3, 0.8, 1.5):
        proc = subprocess.Popen([sys.executable, "-m", "history", "record", "--db", str(db), "--export", str(ex),
                                 str(p)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        try:
            proc.wait(timeout=delay)
        except subprocess.TimeoutExpired:
            proc.send_signal(signal.SIGTERM)
        rc = proc.wait(timeout=120)
        err = proc.stderr.read()
        proc.stdout.close()
        proc.stderr.close()
        # -15: the signal came before Python had started the tool (a loaded machine takes over
        # 0.3 s to start it) and ended it by the default action, the shell's 143 too.
        assert rc in (0, 143, -signal.SIGTERM) and "Traceback" not in err, err
        assert leftovers(tmp_path) == []
        stored = count(db) if db.exists() else 0
        files = len(list(ex.glob("*.jsonl"))) if ex.exists() else 0
        if rc == 0 or stored:  # 143 with the run stored: the signal came after the COMMIT
            assert (stored, files) == (1, 1), err
            assert rc == 0 or "stored before it came" in err, err
            break
        assert files == 0, err  # all or nothing (before: "cannot rollback - no transaction is active", exit 2)


# ---- git ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("how", ["json", "option"])
def test_a_revision_starting_with_dashes_never_reaches_git_as_an_option(tmp_path, how):
    target = tmp_path / "created-by-git"
    rev = f"--output={target}"
    if how == "json":
        r = hist("record", "--db", tmp_path / "h.sqlite", "--export", "", bench(tmp_path / "b.json", git_revision=rev),
                 cwd=ROOT)
    else:
        r = hist("record", "--db", tmp_path / "h.sqlite", "--export", "", f"--commit={rev}", QUICK, cwd=ROOT)
    assert "not a git revision" in one_line_error(r)
    assert not list(tmp_path.glob("created-by-git*"))


def test_git_helpers_put_the_revision_after_end_of_options(tmp_path):
    sys.path.insert(0, TOOLS)
    from history import importer
    target = tmp_path / "out"
    for fn in (importer._full_sha, importer._commit_date, importer._commit_seq):
        fn(f"--output={target}", str(ROOT))
    assert not list(tmp_path.iterdir())


def test_a_commit_with_slashes_stays_inside_the_export_folder(tmp_path):
    ex = tmp_path / "a" / "runs"
    hist("record", "--db", tmp_path / "h.sqlite", "--export", ex, "--commit", "x/../../../escaped", QUICK, check=0)
    assert len(list(ex.iterdir())) == 1 and sorted(p.name for p in tmp_path.iterdir()) == ["a", "h.sqlite"]


# ---- what the terminal, Markdown and the dashboard show ----------------------------------------------

EVIL = "bm/\x1b]0;owned\x07\x1b[2J\rforged line\n+99.00%  exact  deadbeef|cell\u2028\u202eevil\x9b31m"


def _instruction_runs(tmp_path, name, machine="m"):
    """A noise-free series with one +10 % step, so `changes` reports the named benchmark."""
    paths = []
    for i, v in enumerate([100.0] * 4 + [110.0] * 4):
        data = {"context": {"host_name": "h", "cpu_model": "c", "num_cpus": 2, "git_revision": f"{i:040x}",
                            "date": f"2026-01-01T00:{i:02d}:00Z", "commit_date": f"2026-01-01T00:{i:02d}:00Z",
                            "machine": machine},
                "benchmarks": [{"name": name, "run_type": "iteration", "repetition_index": 0, "real_time": v,
                                "cpu_time": v, "time_unit": "instructions", "iterations": 1}]}
        paths.append(tmp_path / f"i{i}.json")
        paths[-1].write_text(json.dumps(data))
    return paths


def _raw_controls(s):
    return [c for c in s if (ord(c) < 32 and c != "\n") or 0x7f <= ord(c) <= 0x9f or c in "\u2028\u2029\u202e"]


def test_terminal_output_escapes_control_characters_in_names(tmp_path):
    db = tmp_path / "h.sqlite"
    r = hist("record", "--db", db, "--export", "", "--machine", "m\x1b[31m\rX", *_instruction_runs(tmp_path, EVIL),
             check=0)
    assert _raw_controls(r.stdout) == [] and r.stdout.count("\n") == 8
    r = hist("changes", "--db", db, "--fail-on-regression", check=1)
    assert _raw_controls(r.stdout + r.stderr) == []
    assert r.stdout.count("\n") == 2 and r.stderr.count("\n") == 1  # header + one change; one regression line
    assert "\\x1b]0;owned\\x07" in r.stdout and "\\x0a+99.00%" in r.stdout
    # A file name with control characters, in an error message.
    bad = tmp_path / "x\x1b[2J\ny.json"
    bad.write_text("{")
    msg = one_line_error(hist("record", "--db", db, bad))
    assert _raw_controls(msg) == []


def test_markdown_output_escapes_pipes_and_newlines(tmp_path):
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", *_instruction_runs(tmp_path, "a|b\nc"), check=0)
    md = hist("changes", "--db", db, "--format", "markdown", check=0).stdout.strip().split("\n")
    assert len(md) == 3 and all(line.count("|") - line.count("\\|") == 7 for line in md)
    assert md[2].endswith("| a\\|b\\x0ac |")


def test_internal_errors_are_exit_3_in_one_line(tmp_path):
    db = record_db(tmp_path)
    code = ("import sys; from history import cli, changes\n"
            "def boom(*a, **k): raise ZeroDivisionError('a bug')\n"
            f"changes.find = boom\nsys.exit(cli.main(['changes', '--db', {str(db)!r}]))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=os.environ | {"PYTHONPATH": TOOLS})
    assert "internal error: ZeroDivisionError: a bug" in one_line_error(r, 3)


@pytest.mark.parametrize("args", [["record"], ["changes", "--max-pvalue", "nan"], ["changes", "--min-change", "-1"],
                                  ["frobnicate"], ["changes", "--benchmark", "("], ["report"],
                                  ["report", "--out", "x", "--commit-url", "javascript:alert(1)//{}"],
                                  ["report", "--out", "x", "--commit-url", 'https://h/{}"></script><script>alert(1)'],
                                  ["report", "--out", "x", "--commit-url", "https://[::1/{}"],
                                  ["report", "--out", "x", "--commit-url", "https://h:port/{}"]])
def test_usage_errors_are_one_line(tmp_path, args):
    db = record_db(tmp_path)
    one_line_error(hist(*args, "--db", db, cwd=tmp_path))
    assert not (tmp_path / "x").exists()


def test_names_matplotlib_would_read_as_tex_draw(tmp_path):
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", *_instruction_runs(tmp_path, "bm/$x^{_$\\frac"), check=0)
    hist("report", "--db", db, "--out", tmp_path / "site", check=0)
    assert len(list((tmp_path / "site" / "png").glob("*.png"))) == 1 and leftovers(tmp_path) == []


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
INJECT = "<img src=x onerror=\"document.body.setAttribute('data-pwned','{}')\">"
SCRIPT = "</script><script>document.body.setAttribute('data-pwned','{}')</script>"


def _dom(tmp_path, site):
    r = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr", "--v=0",
                        f"--user-data-dir={tmp_path / 'profile'}", "--virtual-time-budget=10000", "--dump-dom",
                        (site / "index.html").as_uri()], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout, [line for line in r.stderr.splitlines() if ":CONSOLE" in line]


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/install-deps.sh installs it)")
def test_dashboard_draws_hostile_names_and_runs_no_injected_script(tmp_path):
    names = ["bm/<!--<script>", "bm/" + SCRIPT.format(1), "bm/" + INJECT.format(2), "bm/\u2028\u2029x",
             "render/cpu/pixel/paper-cornell/256x256/spp:800/bounces:2/uniform/<!--</script>"]
    db = tmp_path / "h.sqlite"
    for k, name in enumerate(names):
        (tmp_path / str(k)).mkdir()
        runs = _instruction_runs(tmp_path / str(k), name, machine="m" + SCRIPT.format(3))
        hist("record", "--db", db, "--export", "", *runs, check=0)
    site = tmp_path / "site"
    hist("report", "--db", db, "--out", site, "--no-png", "--commit-url", "https://example.org/c/{}?a=1&b=2",
         check=0)
    html = (site / "index.html").read_text()
    assert "<!--" not in html.split('id="history-data"')[1] and html.count("</script>") == 2
    dom, console = _dom(tmp_path, site)
    assert console == []
    assert "data-pwned" not in dom.split("<body")[1].split(">")[0]
    assert 'data-drawn="5"' in dom and 'data-headline="1"' in dom
    assert 'href="https://example.org/c/' in dom and "&amp;b=2" in dom


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/install-deps.sh installs it)")
def test_dashboard_first_screen_is_the_headline_plots_with_the_table_collapsed(tmp_path):
    """issue 29: the paper frame per machine and device first, the latest-vs-baseline table below, closed."""
    frame = "render/{}/{}/paper-cornell/256x256/spp:800/bounces:2/uniform/manual_time"
    db = tmp_path / "h.sqlite"
    for k, (device, strategy) in enumerate([("cpu", "pixel"), ("cpu", "wavefront"), ("gpu", "pixel")]):
        d = tmp_path / f"s{k}"
        d.mkdir()
        hist("record", "--db", db, "--export", "", *_instruction_runs(d, frame.format(device, strategy)), check=0)
    d = tmp_path / "other"
    d.mkdir()
    hist("record", "--db", db, "--export", "", *_instruction_runs(d, "raycast/cpu/other"), check=0)
    site = tmp_path / "site"
    hist("report", "--db", db, "--out", site, "--no-png", check=0)
    dom, console = _dom(tmp_path, site)
    assert console == []
    # One chart per machine and device (CPU: pixel and wavefront as two coloured lines; GPU), then every series.
    assert 'data-headline="2"' in dom and 'data-drawn="4"' in dom
    assert dom.count('class="median c0"') == 1 and dom.count('class="median c1"') == 1
    assert dom.index('id="headline"') < dom.index('id="summary-box"') < dom.index('id="plots"')
    details = dom[dom.index("<details"):].split(">")[0]
    assert "open" not in details
    headline = dom[dom.index('id="headline"'):dom.index('id="summary-box"')]
    assert headline.count('class="cp slower"') == 3 and "raycast/cpu/other" not in headline


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/install-deps.sh installs it)")
def test_values_near_the_double_range_draw_in_the_png_and_the_page(tmp_path):
    """1.7e308 and 5e-324 side by side: no overflow in the medians, the PNG or the SVG axes."""
    vals = [1.7e308, 1e308, 1.7e308, 5e-324, 0.0, 1.7e308, 1e-300, 1.7e308]
    paths = []
    for i, v in enumerate(vals):
        data = {"context": {"host_name": "h", "cpu_model": "c", "num_cpus": 2, "git_revision": f"{i:040x}",
                            "date": f"2026-01-01T00:{i:02d}:00Z", "commit_date": f"2026-01-01T00:{i:02d}:00Z"},
                "benchmarks": [{"name": n, "run_type": "iteration", "repetition_index": r, "real_time": v / (1 + r),
                                "time_unit": u, "iterations": 1, "rays_per_second": 1e308}
                               for n, u in (("a/x", "ms"), ("b/instr", "instructions")) for r in range(2)]}
        paths.append(tmp_path / f"r{i}.json")
        paths[-1].write_text(json.dumps(data))
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", *paths, check=0)
    hist("changes", "--db", db, "--json", check=0)
    site = tmp_path / "site"
    hist("report", "--db", db, "--out", site, check=0)
    assert len(list((site / "png").glob("*.png"))) == 2
    dom, console = _dom(tmp_path, site)
    assert console == [] and 'data-drawn="4"' in dom and "NaN" not in dom and "Infinity" not in dom


def test_backfill_range_is_never_an_option(tmp_path):
    target = tmp_path / "created-by-git"
    for rng in (f"--output={target}", f"HEAD --output={target}"):
        r = hist("backfill", "--repo", ROOT, "--scratch", tmp_path / "s", "--json-dir", tmp_path / "j", "--", rng)
        assert r.returncode == 2 and "not a revision range" in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert not list(tmp_path.glob("created-by-git*"))
    one_line_error(hist("backfill", "--wall", "many"))
    (tmp_path / "afile").write_text("x")
    assert "git log" in one_line_error(hist("backfill", "--db", tmp_path / "h.sqlite", "--repo", tmp_path / "afile",
                                            "--git-results", tmp_path / "afile"))


def test_a_database_edited_to_hold_text_for_a_value_is_exit_2(tmp_path):
    db = edited_db(tmp_path, "UPDATE results SET value='fast' WHERE rowid=1")
    assert "not a number" in one_line_error(hist("changes", "--db", db))
    assert "not a number" in one_line_error(hist("report", "--db", db, "--out", tmp_path / "site", "--no-png"))


def test_a_fifo_or_device_is_not_read_and_an_empty_path_is_a_usage_error(tmp_path):
    fifo = tmp_path / "fifo.json"
    os.mkfifo(fifo)
    assert "not a regular file" in one_line_error(hist("record", "--db", tmp_path / "h.sqlite", fifo, timeout=30))
    assert "not a regular file" in one_line_error(hist("record", "--db", tmp_path / "h.sqlite", "/dev/zero",
                                                       timeout=30))
    for args in (["record", "--db", "", QUICK], ["changes", "--db", ":memory:"], ["report", "--out", ""]):
        assert "give a path" in one_line_error(hist(*args, cwd=tmp_path))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo.json"]


def test_a_lock_held_past_the_busy_timeout_is_exit_2_and_leaves_nothing(tmp_path):
    db, ex = record_db(tmp_path), tmp_path / "runs"
    holder = sqlite3.connect(db, isolation_level=None)
    holder.execute("BEGIN EXCLUSIVE")
    try:
        env = os.environ | {"PYTHONPATH": TOOLS, "PATHBENCH_HISTORY_BUSY_TIMEOUT": "1"}
        r = subprocess.run([sys.executable, "-m", "history", "record", "--db", str(db), "--export", str(ex),
                            str(bench(tmp_path / "b.json", git_revision="1" * 40))], capture_output=True, text=True,
                           env=env, timeout=60)
    finally:
        holder.execute("ROLLBACK")
        holder.close()
    assert "database is locked" in one_line_error(r)
    assert count(db) == 1 and (not ex.exists() or list(ex.iterdir()) == []) and leftovers(tmp_path) == []


def test_a_signal_during_a_long_lock_wait_ends_the_run_quickly_and_leaves_nothing(tmp_path):
    """SIGTERM while `record` waits in sqlite's busy handler (C code, where Python signal handlers do
    not run): ended within the grace time, its staged run file removed, the database untouched."""
    db, ex = record_db(tmp_path), tmp_path / "runs"
    before = db.read_bytes()
    holder = sqlite3.connect(db, isolation_level=None)
    holder.execute("BEGIN IMMEDIATE")  # readers go on: record stages its run file, then waits to write
    try:
        proc = subprocess.Popen([sys.executable, "-m", "history", "record", "--db", str(db), "--export", str(ex),
                                 str(bench(tmp_path / "b.json", git_revision="2" * 40))], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, env=os.environ | {"PYTHONPATH": TOOLS})
        for _ in range(200):  # until its run file is staged: it is then waiting for the lock
            if ex.exists() and list(ex.iterdir()):
                break
            time.sleep(0.05)
        proc.send_signal(signal.SIGTERM)
        t0 = time.monotonic()
        rc = proc.wait(timeout=60)
        waited = time.monotonic() - t0
        err = proc.stderr.read()
        proc.stdout.close()
        proc.stderr.close()
    finally:
        holder.execute("ROLLBACK")
        holder.close()
    assert rc == 143 and "stopped by signal 15" in err and err.count("\n") == 1, err
    assert waited < 15 and list(ex.iterdir()) == [] and leftovers(tmp_path) == [] and db.read_bytes() == before


def test_a_fifo_given_as_the_database_is_refused_not_waited_on(tmp_path):
    fifo = tmp_path / "h.sqlite"
    os.mkfifo(fifo)
    for args in (["changes"], ["record", QUICK], ["report", "--out", tmp_path / "site"]):
        assert "not a regular file" in one_line_error(hist(*args[:1], "--db", fifo, *args[1:], timeout=30))


def test_a_missing_tool_package_is_named_in_one_line(tmp_path):
    """Otava absent (as in a Python without tools/requirements.txt): exit 2 naming it, not a traceback."""
    db = tmp_path / "h.sqlite"
    hist("record", "--db", db, "--export", "", *_instruction_runs(tmp_path, "x"), check=0)
    code = ("import sys; sys.modules['otava'] = None\n"
            "from history import cli\n"
            f"sys.exit(cli.main(['changes', '--otava-only', '--db', {str(db)!r}]))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=os.environ | {"PYTHONPATH": TOOLS})
    assert "otava" in one_line_error(r) and "requirements.txt" in r.stderr


def test_the_signal_watcher_takes_only_its_signals(monkeypatch):
    """CPython 3.11's sigtimedwait returns a zeroed siginfo (si_signo 0), not None, when another
    signal interrupted the wait and its timeout ran out: the watcher took that for a signal and
    died with a traceback (ValueError: signal number out of range; 3 of 90 `history record`
    runs under load). It must go on waiting, and leave the main thread alone."""
    import threading
    import types
    sys.path.insert(0, TOOLS)
    from history import cli
    done, waits = threading.Event(), []

    def sigtimedwait(signals, timeout):
        waits.append(timeout)
        if len(waits) == 3:
            done.set()
        return types.SimpleNamespace(si_signo=0)

    monkeypatch.setattr(cli.signal, "sigtimedwait", sigtimedwait)
    cli._watch(done)  # returns once the run is done, without interrupting it
    assert len(waits) == 3


def test_a_signal_right_after_the_commit_keeps_the_run_whole(tmp_path):
    """The watcher's Stopped can land between COMMIT and the end of insert_all: ROLLBACK then
    failed ("cannot rollback - no transaction is active", exit 2) and the run files of a stored
    run were removed. Now the run stays whole, and the message says it was stored."""
    sys.path.insert(0, TOOLS)
    from history import cli, importer, store
    run = importer.parse(str(QUICK))
    real = store.connect(str(tmp_path / "h.sqlite"))

    class SignalAfterCommit:
        in_transaction = property(lambda self: real.in_transaction)

        def execute(self, sql, *args):
            out = real.execute(sql, *args)
            if sql == "COMMIT":
                raise cli.Stopped(signal.SIGTERM)
            return out

        def executemany(self, sql, rows):
            return real.executemany(sql, rows)

    with pytest.raises(cli.Stopped) as e:
        importer.insert_all(SignalAfterCommit(), [run], export_dir=str(tmp_path / "runs"))
    real.close()
    assert getattr(e.value, "stored", False)
    assert count(tmp_path / "h.sqlite") == 1 and len(list((tmp_path / "runs").glob("*.jsonl"))) == 1
