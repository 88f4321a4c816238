"""tools/merge_bench_json.py joins the parts of one preset's run (scripts/device/gpu_bench_scaling.sh):
the benchmarks in the parts' order, the union of their film hashes with film_hash recomputed as
pathbench-bench computes it, and each part's date and load; parts of different builds or machines,
a benchmark in two parts, or a file that is not benchmark JSON exit 2 with one line and write nothing."""
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TOOL = ROOT / "tools" / "merge_bench_json.py"
sys.path.insert(0, str(ROOT / "tools"))
import merge_bench_json  # noqa: E402


def part(tmp_path, name, rows, date, revision="abc123", machine="m1"):
    hashes = {r: f"fnv1a64:{i:016x}" for i, r in enumerate(rows)}
    doc = {"context": {"date": date, "load_avg": [1.0, 2.0, 3.0], "git_revision": revision, "machine_id": machine,
                       "gpu_name": "NVIDIA H100 80GB HBM3", "pathbench_preset": "scaling", "film_hashes": hashes,
                       "film_hash": "fnv1a64:0"},
           "benchmarks": [{"name": r, "real_time": 1.0 + i} for i, r in enumerate(rows)]}
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(doc))
    return path


def run(*args):
    return subprocess.run([sys.executable, str(TOOL), *map(str, args)], capture_output=True, text=True, timeout=60)


def test_fnv1a64_is_pathbench_benchs():
    # FNV-1a 64 of "a": the published test vector.
    assert merge_bench_json.fnv1a64("a") == 0xAF63DC4C8601EC8C
    assert merge_bench_json.fnv1a64("") == 0xCBF29CE484222325


def test_merges_parts_in_order_with_their_film_hashes(tmp_path):
    a = part(tmp_path, "a", ["render/gpu/pixel/x", "render/gpu/pixel/y"], "2026-11-28T05:32:00")
    b = part(tmp_path, "b", ["render/gpu/wavefront/x"], "2026-11-28T05:34:09")
    out = tmp_path / "merged.json"
    r = run(out, a, b)
    assert r.returncode == 0, r.stderr
    m = json.loads(out.read_text())
    assert [x["name"] for x in m["benchmarks"]] == ["render/gpu/pixel/x", "render/gpu/pixel/y", "render/gpu/wavefront/x"]
    hashes = m["context"]["film_hashes"]
    assert list(hashes) == sorted(hashes) and len(hashes) == 3
    text = "".join(f"{k}={v}\n" for k, v in hashes.items())
    assert m["context"]["film_hash"] == "fnv1a64:{:016x}".format(merge_bench_json.fnv1a64(text))
    assert [p["file"] for p in m["context"]["merged_from"]] == ["a.json", "b.json"]
    assert m["context"]["merged_from"][1]["date"] == "2026-11-28T05:34:09"
    assert m["context"]["date"] == "2026-11-28T05:32:00"  # the first part's context
    assert not list(tmp_path.glob(".merged.json*"))  # the temporary file renamed, none left


def test_keeps_a_nan_counter_as_google_benchmark_writes_it(tmp_path):
    a = part(tmp_path, "a", ["r/x"], "d1")
    doc = json.loads(a.read_text())
    doc["benchmarks"][0]["rays_per_joule"] = float("nan")
    a.write_text(json.dumps(doc))
    out = tmp_path / "merged.json"
    assert run(out, a).returncode == 0
    assert "NaN" in out.read_text()


def test_refuses_parts_that_do_not_belong_together(tmp_path):
    a = part(tmp_path, "a", ["r/x"], "d1")
    other_build = part(tmp_path, "b", ["r/y"], "d2", revision="def456")
    other_machine = part(tmp_path, "c", ["r/y"], "d2", machine="m2")
    twice = part(tmp_path, "d", ["r/x"], "d2")
    not_json = tmp_path / "e.json"
    not_json.write_text("{ not json")
    no_benchmarks = tmp_path / "f.json"
    no_benchmarks.write_text(json.dumps({"context": {}}))
    fifo = tmp_path / "g.json"
    os.mkfifo(fifo)  # would block a reader that opened it
    huge = tmp_path / "h.json"
    with open(huge, "wb") as f:
        f.truncate((64 << 20) + 1)
    for bad, says in [(other_build, "git_revision"), (other_machine, "machine_id"), (twice, "r/x"),
                      (not_json, "e.json"), (no_benchmarks, "not a Google Benchmark JSON"),
                      (tmp_path / "missing.json", "missing.json"), (fifo, "not a regular file"),
                      (Path("/dev/zero"), "not a regular file"), (huge, "larger than 64 MiB")]:
        out = tmp_path / "merged.json"
        r = run(out, a, bad)
        assert r.returncode == 2, (bad, r.stdout, r.stderr)
        assert says in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert not list(tmp_path.glob("*merged.json*"))  # no output, no temporary file


def test_an_output_it_cannot_write_is_one_line(tmp_path):
    a = part(tmp_path, "a", ["r/x"], "d1")
    out = tmp_path / "no such folder" / "merged.json"
    r = run(out, a)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "merged.json" in r.stderr, r.stderr
    assert not out.parent.exists()


def test_usage_without_parts(tmp_path):
    r = run(tmp_path / "merged.json")
    assert r.returncode == 2 and "PART.json" in r.stderr
    assert not (tmp_path / "merged.json").exists()
