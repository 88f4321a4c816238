"""Helpers of the Python tools that need no renderer: the machine slug (same rule as
pb::machine_slug), the reference statistics, the speed report's Markdown and its raw-Embree ray mix."""
import numpy as np
import pytest

import machine
import make_reference
import mitsuba_speed
import raw_embree_mix


@pytest.mark.parametrize("model, slug", [
    ("AMD EPYC 7B13 64-Core Processor", "amd-epyc-7b13-64-core"),
    ("Intel(R) Xeon(R) CPU @ 2.20GHz", "intel-r-xeon-r-cpu-2-20ghz"),
    ("AMD EPYC", "amd-epyc"),
    ("  Some  CPU  ", "some"),
    ("Neoverse-N1 CPU processor", "neoverse-n1"),
    ("", "unknown-machine"),
])
def test_machine_slug(model, slug):
    assert machine.machine_slug(model) == slug


def test_machine_slug_of_this_machine_is_a_folder_name():
    s = machine.machine_slug()
    assert s and all(c.isalnum() or c == "-" for c in s) and s == s.lower()


def test_reference_from_passes():
    rng = np.random.default_rng(1)
    passes = rng.normal(2.0, 0.5, size=(64, 4, 5, 3))
    passes[:, 0, 0, :] = 10.0  # a constant pixel: variance exactly 0
    mean, var = make_reference.reference_from_passes(passes)
    assert mean.shape == var.shape == (4, 5, 3)
    assert np.allclose(mean, passes.mean(axis=0))
    assert np.allclose(var, passes.var(axis=0, ddof=1) / 64)
    assert (var[0, 0] == 0).all() and (mean[0, 0] == 10).all()
    with pytest.raises(ValueError):
        make_reference.reference_from_passes(passes[:1])


def _speed_result():
    return {
        "date": "2026-01-01 00:00 UTC",
        "machine": {"slug": "x", "cpu": "Test CPU", "hardware_threads": 2},
        "settings": {"width": 256, "height": 256, "spp": 800},
        "load_average_before": [0.1, 0.1, 0.1], "load_average_after": [1.0, 1.0, 1.0],
        "mitsuba": {"renderer": "Mitsuba 3.9.1", "variant": "llvm_ad_rgb", "median_seconds": 40.0,
                    "seconds": [40.0, 41.0, 39.0], "warmup_seconds": 50.0, "estimated_rays_per_second": 5.8e6,
                    "rays_per_sample_assumed": 4.4, "image_mean_rgb": [0.5, 0.5, 0.45]},
        "pathbench": {"pixel": {"median_seconds": 20.0, "seconds": [20.0, 21.0, 19.0],
                                "median_rays_per_second": 11.5e6, "image_mean_rgb": [0.5, 0.5, 0.45],
                                "git_revision": "abc", "compiler": "gcc"}},
    }


def test_speed_markdown():
    res = _speed_result()
    md = mitsuba_speed.markdown(res)
    assert "| pathbench cpu/pixel | 20.00" in md
    assert "2.00x" in md
    assert "estimate" in md
    assert "Embree layout" not in md  # reports from before the layout choice have none


def test_speed_markdown_names_the_embree_layout():
    res = _speed_result()
    res["pathbench"]["pixel"]["embree_layout"] = {
        "asked": "auto", "used": "quads", "why": "quads measured faster",
        "probe_ns_per_ray": {"triangles": 94.0, "quads": 68.0}}
    md = mitsuba_speed.markdown(res)
    assert ("pathbench's Embree layout (`--embree-layout auto`): "
            "pixel: quads (quads measured faster, probe 94 ns/ray as triangles, 68 as quads).") in md
    assert "raw rates above" not in md  # none measured (--no-raw): none referred to
    res["raw_embree"] = {"rates": {}, "rounds": 1, "mix": {}}
    assert "(`--embree-layout auto`; the raw rates above come from the same choice): " in mitsuba_speed.markdown(res)


def _rates(camera, bounce, shadow, width):
    return {raw_embree_mix.bench_name("camera", width): camera, raw_embree_mix.bench_name("bounce", width): bounce,
            raw_embree_mix.bench_name("shadow", width): shadow}


def test_raw_mix_rate_is_the_harmonic_mix():
    rays = {"camera": 100, "bounce": 50, "shadow": 250, "total": 400}
    # Equal rates: the mix runs at that rate.
    assert raw_embree_mix.mix_rate(rays, _rates(8.0, 8.0, 8.0, "1"), "pixel") == pytest.approx(8.0)
    # Otherwise: total rays over the seconds each kind takes at its own rate.
    rates = _rates(10.0, 5.0, 25.0, "1") | _rates(20.0, 10.0, 50.0, "16")
    assert raw_embree_mix.mix_rate(rays, rates, "pixel") == pytest.approx(400 / (10 + 10 + 10))
    assert raw_embree_mix.mix_rate(rays, rates, "wavefront") == pytest.approx(400 / (5 + 5 + 5))


def test_speed_markdown_with_raw_embree():
    res = _speed_result()
    res["pathbench"]["pixel"] |= {"median_rays_per_second": 12e6,
                                  "rays": {"camera": 52e6, "bounce": 50e6, "shadow": 85e6, "total": 187e6}}
    res["raw_embree"] = {"rates": _rates(20e6, 16e6, 18e6, "1"), "rounds": 1,
                         "mix": {"pixel": {"calls": "rtcIntersect1 / rtcOccluded1", "raw_rays_per_second": 16e6,
                                           "share": 0.75}}}
    md = mitsuba_speed.markdown(res)
    assert "| pixel | 52.0 M / 50.0 M / 85.0 M | rtcIntersect1 / rtcOccluded1 | 16.0 M | 12.0 M | 75% |" in md
    assert "intersect1/coherent 20.0" in md


def test_speed_runner_passes_options_with_values(tmp_path):
    r = mitsuba_speed.PathbenchRunner("pathbench", "wavefront/isa=avx2/no-watertight", 8, 16, tmp_path)
    assert r.strategy == "wavefront"
    assert r.flags == ["--isa", "avx2", "--no-watertight"]
    assert not r.watertight


def test_speed_markdown_names_cpu_flags_and_isa():
    res = _speed_result()
    res["machine"]["cpu_flags"] = ["avx2", "avx512f"]
    res["pathbench"]["pixel"]["isa"] = "avx512"
    md = mitsuba_speed.markdown(res)
    assert "CPU vector flags: avx2 avx512f; pathbench's path step ran pixel: avx512." in md


def test_cpu_vector_flags_reads_cpuinfo(tmp_path):
    from machine import cpu_vector_flags
    f = tmp_path / "cpuinfo"
    f.write_text("model name\t: X\nflags\t\t: fpu sse4_2 avx2 avx512vl avx512f\n")
    assert cpu_vector_flags(str(f)) == ["sse4_2", "avx2", "avx512f", "avx512vl"]


def test_raw_shares_per_isa():
    rates = _rates(10.0, 5.0, 25.0, "1") | _rates(20.0, 10.0, 50.0, "16")
    rays = {"camera": 100, "bounce": 50, "shadow": 250, "total": 400}
    reports = [{"strategy": "wavefront", "isa": i, "rays": rays, "rays_per_second": v} for i, v in
               (("avx512", 20.0), ("avx2", 10.0))]
    out = raw_embree_mix.shares(reports, rates)
    assert [(s["isa"], s["share"]) for s in out] == [("avx512", round(20.0 / (400 / 15), 4)),
                                                      ("avx2", round(10.0 / (400 / 15), 4))]


def test_machine_id_agrees_with_the_render_report(tmp_path):
    """tools/machine.py and pathbench's C++ fingerprint name this machine alike (fixture
    machines: tests/bench/test_fingerprint.cpp)."""
    import json
    import subprocess
    from pathlib import Path
    exe = Path(__file__).resolve().parents[2] / "build" / "bin" / "pathbench"
    if not exe.exists():
        pytest.skip("build/bin/pathbench not built")
    report = tmp_path / "r.json"
    subprocess.run([str(exe), "render", "--scene", "paper-cornell", "--width", "8", "--height", "8", "--spp", "1",
                    "--quiet", "--report", str(report)], check=True)
    fp = json.loads(report.read_text())["fingerprint"]
    host = machine.host_fingerprint()
    assert fp["machine_id"] == host["machine_id"]
    assert fp["cpu"] == host["cpu"]


def test_slugify_is_the_cpp_rule():
    assert machine.slugify("cornell-box:mirror", "x") == "cornell-box-mirror"
    assert machine.slugify("caf\u00e9 GPU", "x") == "caf-gpu"
    assert machine.slugify(" -- ", "scene") == "scene"


def _emulated_result():
    import isa_emulation
    from pathlib import Path
    res = _speed_result()
    res["machine"]["cpu_flags"] = ["avx2", "avx512f"]
    res["pathbench"] = {"pixel/isa=avx2": res["pathbench"]["pixel"] | {"isa": "avx2"}}
    widths = {"native_packet_widths": [4, 8]}
    drjit = {"native": {"cpu": "znver4", "features": "+avx512f", "vector_width": 16},
             "asked": {"cpu": "haswell", "features": "+avx2,-avx512f", "vector_width": 8},
             "read_back": {"cpu": "haswell", "features": "+avx2,-avx512f", "vector_width": 8},
             "probe": {"disassembly_lines": 50, "zmm_instructions": 0, "ymm_instructions": 40},
             "native_probe": {"disassembly_lines": 40, "zmm_instructions": 36, "ymm_instructions": 0}}
    mitsuba_embree = {"devices": 1, "library": "mitsuba-embree", "max_isa": "avx2",
                      "config": "threads=2,max_isa=avx2", "created": True, "native_packet_widths": [4, 8]}
    res["emulation"] = isa_emulation.record("avx2", Path("/x/libembree_isa_cap.so"), drjit, mitsuba_embree,
                                            {"pixel/isa=avx2": widths}, widths, {"pixel/isa=avx2": "avx2"},
                                            {"isa_compiled": ["sse2"], "cxx_flags": "-O3"})
    return res


def test_speed_markdown_states_the_emulation():
    res = _emulated_result()
    md = mitsuba_speed.markdown(res)
    assert md.startswith("# Mitsuba 3 vs pathbench on Test CPU, emulating an AVX2-only host\n")
    assert ("**Emulated AVX2-only host.** This is an AVX-512 host with every component capped at AVX2, NOT a real "
            "AVX2-only host") in md
    assert "pathbench's path step `--isa avx2` (ran: pixel/isa=avx2: avx2)" in md
    assert ("pathbench pixel/isa=avx2 widths 4/8; pathbench-bench (raw rates) widths 4/8; Mitsuba's bundled Embree "
            "widths 4/8 (config `threads=2,max_isa=avx2`)") in md
    assert ("Dr.Jit's LLVM backend set to cpu `haswell`, vector width 8, features `+avx2,-avx512f` (native: `znver4`, "
            "width 16); a probe kernel's disassembly has 0 zmm and 40 ymm instructions (the same kernel for the "
            "native target: 36 zmm, 0 ymm)") in md
    assert "Re-run: `.venv/bin/python tools/mitsuba_speed.py --emulate-isa avx2`" in md
    assert "emulat" not in mitsuba_speed.markdown(_speed_result()).lower()  # native results say nothing of it


def test_speed_emulation_json_record():
    import json
    em = json.loads(json.dumps(_emulated_result()["emulation"]))  # all of it goes into the JSON
    assert em["isa"] == "avx2" and "NOT a real AVX2-only host" in em["statement"]
    assert set(em["covered"]) == {"pathbench_path_step", "embree", "drjit_llvm", "glibc"}
    assert em["covered"]["embree"]["mitsuba"]["native_packet_widths"] == [4, 8]
    assert em["covered"]["drjit_llvm"]["read_back"]["vector_width"] == 8
    assert mitsuba_speed.results_stem("avx2") == "mitsuba-vs-pathbench-avx2cap"
    assert mitsuba_speed.results_stem() == "mitsuba-vs-pathbench"  # the native results' names are kept


def test_speed_emulation_forces_the_isa_of_every_spec():
    assert mitsuba_speed.emulated_specs(["pixel", "wavefront/no-watertight", "pixel/isa=avx2"], "avx2") == [
        "pixel/isa=avx2", "wavefront/no-watertight/isa=avx2"]
    with pytest.raises(SystemExit):
        mitsuba_speed.emulated_specs(["pixel/isa=avx512"], "avx2")


def test_speed_emulation_checks_refuse_an_uncapped_run():
    import isa_emulation
    ok = {"isa": "avx2", "fingerprint": {"build": {"isa_compiled": ["sse2"], "cxx_flags": "-O3"},
                                         "embree": {"isa_derived": "avx2", "native_packet_widths": [4, 8]}}}
    isa_emulation.check_pathbench_report(ok, "run", "avx2")
    bad = [ok | {"isa": "avx512"},
           ok | {"fingerprint": ok["fingerprint"] | {"embree": {"isa_derived": "avx512",
                                                                "native_packet_widths": [4, 8, 16]}}},
           ok | {"fingerprint": ok["fingerprint"] | {"embree": None}},
           ok | {"fingerprint": ok["fingerprint"] | {"build": {"isa_compiled": ["sse2"],
                                                               "cxx_flags": "-O3 -march=native"}}}]
    for r in bad:
        with pytest.raises(RuntimeError):
            isa_emulation.check_pathbench_report(r, "run", "avx2")
    with pytest.raises(RuntimeError):
        isa_emulation.check_drjit({"read_back": {"features": "+avx512f"}}, "avx2")
    with pytest.raises(RuntimeError):
        isa_emulation.check_drjit({"read_back": {"features": "+avx2"}, "probe": {"zmm_instructions": 3}}, "avx2")


def test_speed_emulation_needs_the_shim_preloaded():
    import isa_emulation
    from pathlib import Path
    if isa_emulation.shim_report() is None:  # pytest itself runs without the shim
        with pytest.raises(SystemExit, match="not preloaded"):
            isa_emulation.ensure_preloaded("avx2", Path("/x/shim.so"), argv=["--emulate-isa", "avx2"])
    assert isa_emulation.glibc_tunables("avx2", None).startswith("glibc.cpu.hwcaps=-AVX512F,")
    assert isa_emulation.glibc_tunables("avx2", "a=1").startswith("a=1:glibc.cpu.hwcaps=")
