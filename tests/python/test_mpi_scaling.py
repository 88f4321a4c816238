"""tools/mpi_scaling.py (issues 30, 31) without MPI or a GPU: a fake `pathbench` and a fake
`mpirun` write images and reports as the real ones do, so the study's bookkeeping (which
runs it compares, what it calls identical, its history document) is tested here."""
import json
import os
import stat
import subprocess
import sys
import textwrap

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import mpi_scaling  # noqa: E402

FAKE_PATHBENCH = textwrap.dedent("""\
    #!{python}
    # A fake `pathbench render`: writes --out and --report; the image's bytes and film hash
    # are the same for every run, except the N-th run of RANKS ranks (env FAKE_BAD_RUN,
    # FAKE_BAD_KIND=film|file), counted in FAKE_COUNTER.
    import json, os, sys
    a = sys.argv[1:]
    get = lambda k: a[a.index(k) + 1]
    ranks = int(os.environ.get("FAKE_RANKS", "1"))
    device = get("--device") if "--device" in a else "cpu"
    counter = os.environ["FAKE_COUNTER"]
    n = int(open(counter).read()) + 1 if os.path.exists(counter) else 1
    open(counter, "w").write(str(n))
    image, film = b"PF\\n1 1\\n-1.0\\n" + b"\\0" * 12, "fnv1a64:0000000000000001"
    if ranks == 2 and str(n) == os.environ.get("FAKE_BAD_RUN"):
        if os.environ.get("FAKE_BAD_KIND") == "film":
            image, film = image[:-1] + b"\\1", "fnv1a64:0000000000000002"
        elif os.environ.get("FAKE_BAD_KIND") == "film_only":  # sums below the image's resolution
            film = "fnv1a64:0000000000000002"
        else:
            image = image + b"\\n"  # the file differs, the film does not
    open(get("--out"), "wb").write(image)
    rep = {{"device": device, "seconds": 0.01 / ranks, "film_download_seconds": 0.001,
           "rays": {{"total": 1000}}, "film_hash": film, "machine": {{"cpu": "fake"}},
           "fingerprint": {{"cpu_model": "fake cpu", "num_cpus": 2}}}}
    if ranks > 1:
        rep["ranks"] = {{"frame_seconds": 0.011 / ranks, "reduce_seconds": 0.0001, "load_balance": 1.0,
                        "parallel_efficiency": 0.9, "reduction": {{"gpu_ranks": "mpi"}},
                        "per_rank": [{{"rank": k, "embree_layout": {{"used": "quads"}}}} for k in range(ranks)]}}
    json.dump(rep, open(get("--report"), "w"))
    """)

FAKE_MPIRUN = textwrap.dedent("""\
    #!{python}
    # A fake mpirun: one process stands for all ranks (FAKE_RANKS = the -np values' sum).
    import os, subprocess, sys
    a = sys.argv[1:]
    nps = [int(a[i + 1]) for i, x in enumerate(a) if x == "-np"]
    first = a.index("-np") + 2
    cmd = a[first:a.index(":")] if ":" in a else a[first:]
    sys.exit(subprocess.call(cmd, env=dict(os.environ, FAKE_RANKS=str(sum(nps)))))
    """)


@pytest.fixture
def fakes(tmp_path):
    paths = {}
    for name, text in (("pathbench", FAKE_PATHBENCH), ("mpirun", FAKE_MPIRUN)):
        p = tmp_path / name
        p.write_text(text.format(python=sys.executable))
        p.chmod(p.stat().st_mode | stat.S_IEXEC)
        paths[name] = str(p)
    return paths


def study(fakes, tmp_path, **env):
    out = tmp_path / "out"
    e = dict(os.environ, FAKE_COUNTER=str(tmp_path / "counter"), **env)
    r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "mpi_scaling.py"), "--pathbench",
                        fakes["pathbench"], "--mpirun", fakes["mpirun"], "--gpus", "0", "--cpu-ranks", "1,2",
                        "--reps", "3", "--quick", "--out-dir", str(out), "--commit", "0" * 40],
                       capture_output=True, text=True, env=e)
    doc = json.loads((out / "mpi-scaling.json").read_text()) if (out / "mpi-scaling.json").exists() else None
    return r, doc, out


def strong(doc, n):
    return next(x for x in doc["runs"] if x["experiment"] == "strong-cpu" and x["ranks"] == n)


def test_identical_runs_pass_and_history_document_records(fakes, tmp_path):
    r, doc, out = study(fakes, tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    two = strong(doc, 2)
    assert two["identical"] is True and two["film_hash_identical"] is True
    assert two["speedup"] == pytest.approx((0.01 + 0.001) / 0.0055)
    assert len(two["seconds_all"]) == 3
    # The history document is one the importer takes: a series per experiment, frame and ranks.
    sys.path.insert(0, ROOT)
    from tools.history import importer

    run = importer.parse(str(out / "mpi-scaling-history.json"), commit="0" * 40, machine="fake-x0")
    names = {x["benchmark"] for x in run["results"]}
    assert "mpi/strong-cpu/paper-cornell/64x64/spp:32/ranks:2" in names
    reps = [x for x in run["results"] if x["benchmark"].endswith("64x64/spp:32/ranks:2")]
    assert sorted(x["repetition"] for x in reps) == [0, 1, 2]
    assert all(x["counters"]["identical"] == 1.0 for x in reps)


@pytest.mark.parametrize("run_no,kind,why", [
    # The 2-rank runs are runs 4-6 (runs 1-3: the one-rank base). The study used to compare the
    # median run's image alone: a different first run (the fastest) went unseen.
    ("4", "film", "the film differs (film_hash)"),
    ("5", "file", "the image file differs while the film is the same"),
    # Seen once on the 2 x H100 host (3 CPU ranks, b23764b): the film's sums differed, the
    # image's bytes did not.
    ("6", "film_only", "the film differs while the image file is the same"),
])
def test_any_repetition_that_differs_is_reported(fakes, tmp_path, run_no, kind, why):
    r, doc, _ = study(fakes, tmp_path, FAKE_BAD_RUN=run_no, FAKE_BAD_KIND=kind)
    assert r.returncode == 1, r.stdout + r.stderr
    two = strong(doc, 2)
    assert two["identical"] is False and two["difference"] == why
    assert f"NOT IDENTICAL: strong-cpu 64x64x32 on 2 ranks: {why}" in r.stdout
    assert strong(doc, 1)["identical"] is True
    assert len(two["film_hash_all"]) == 3 and two["base_film_hash"] == "fnv1a64:0000000000000001"
    assert two["rank_layouts_all"] == [["quads", "quads"]] * 3  # the layout each rank traced, each repetition
    assert (two["film_hash_all"][int(run_no) - 4] != two["base_film_hash"]) == (kind != "file")


def test_gpu_counts():
    assert mpi_scaling.gpu_counts(1) == [1]
    assert mpi_scaling.gpu_counts(4) == [1, 2, 4]
    assert mpi_scaling.gpu_counts(6) == [1, 2, 4, 6]
    assert mpi_scaling.gpu_counts(8) == [1, 2, 4, 8]


def _report(seconds, ranks=None, reduce=None, bands=None, film="fnv1a64:1"):
    rep = {"seconds": seconds, "film_download_seconds": 0.0, "film_hash": film}
    if ranks:
        rep["ranks"] = {"frame_seconds": seconds, "reduce_seconds": reduce,
                        "reduction": {"share_of_frame": reduce / seconds, "bands": bands}}
    return rep


def test_ab_summary_rounds_ratios_and_hashes(tmp_path):
    """tools/mpi_scaling_ab.py: per-round ratios base / arm, medians, and one film hash per
    frame (or the differing hashes named)."""
    import mpi_scaling_ab

    cache, bands = tmp_path / "cache", tmp_path / "bands"
    cache.mkdir()
    bands.mkdir()
    for i, (g, on, off) in enumerate([(0.010, 0.0098, 0.0104), (0.011, 0.0105, 0.0110), (0.012, 0.0130, 0.0125)], 1):
        (cache / f"gpu-256-{i}.json").write_text(json.dumps(_report(g)))
        (cache / f"on-256-{i}.json").write_text(json.dumps(_report(on, 2, 0.0001, 1)))
        (cache / f"off-256-{i}.json").write_text(json.dumps(_report(off, 2, 0.0001, 1)))
    for i in (1, 2):
        (bands / f"b1-2048-{i}.json").write_text(json.dumps(_report(0.464, 2, 0.0028, 1)))
        (bands / f"bauto-2048-{i}.json").write_text(json.dumps(_report(0.462, 2, 0.0005, 8,
                                                                        film="fnv1a64:2" if i == 2 else "fnv1a64:1")))
    (bands / "notes.txt").write_text("ignored")
    assert mpi_scaling_ab.main([str(tmp_path)]) == 0
    doc = json.loads((tmp_path / "ab.json").read_text())
    on = next(r for r in doc["cache"]["rows"] if r["arm"] == "on")
    assert on["round_ratios"] == pytest.approx([0.010 / 0.0098, 0.011 / 0.0105, 0.012 / 0.0130])
    assert on["ratio"]["median"] == pytest.approx(0.010 / 0.0098)  # of 1.020, 1.048, 0.923
    assert on["seconds"]["median"] == pytest.approx(0.0105)
    gpu = next(r for r in doc["cache"]["rows"] if r["arm"] == "gpu")
    assert "round_ratios" not in gpu and gpu["reduce_seconds"] == {}
    auto = next(r for r in doc["bands"]["rows"] if r["arm"] == "bauto")
    assert auto["bands"] == [8] and auto["reduce_share"]["median"] == pytest.approx(0.0005 / 0.462)
    assert doc["cache"]["film_hashes_per_width"] == {"256": ["fnv1a64:1"]}
    assert doc["bands"]["film_hashes_per_width"]["2048"] == ["fnv1a64:1", "fnv1a64:2"]


def test_ab_summary_refuses_an_empty_folder(tmp_path, capsys):
    import mpi_scaling_ab

    assert mpi_scaling_ab.main([str(tmp_path)]) == 2
    assert "neither cache/ nor bands/" in capsys.readouterr().err
