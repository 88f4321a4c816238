"""tools/feature_specialisation.py without building anything: the report it writes."""
import feature_specialisation as fs


def result(normal, diffuse, slowdown):
    return {"normal": normal, "diffuse_only": diffuse, "ratio": normal / diffuse, "slowdown": slowdown,
            "within_limit": slowdown <= fs.MAX_SLOWDOWN}


def test_markdown_has_one_table_per_method_and_flags_a_slow_build():
    common = {"measure": "m", "render": "r", "machine": "AMD EPYC", "git_revision": "abc",
              "load_average_before": [1, 1, 1], "load_average_after": [1, 1, 1], "note": "note"}
    doc = {"methods": {
        "callgrind": dict(common, strategies={"pixel": result(101.0, 100.0, 0.01)}),
        "wallclock": dict(common, strategies={"wavefront": result(90.0, 100.0, 100.0 / 90.0 - 1)}),
    }}
    md = fs.markdown(doc)
    assert "## callgrind" in md and "## wallclock" in md
    assert "| pixel | 101 | 100 | 1.0100 | +1.00 % | yes |" in md
    assert "| wavefront | 90 | 100 | 0.9000 | +11.11 % | NO |" in md
    assert fs.MAX_SLOWDOWN == 0.03
