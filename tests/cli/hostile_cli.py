#!/usr/bin/env python3
"""Hostile input through the `pathbench` binary, as a fuzzer would write it (issue 34):
every case must end with exit status 2 and one message line on stderr naming the file
and the field (or, for an input that is odd but valid, a verdict), never status 3 or a
crash; names with control characters never reach the terminal raw, and Markdown tables
keep their cells.

    hostile_cli.py --pathbench build/bin/pathbench --surface compare|sizes|crosscheck --tmp DIR

Registered with CTest (tests/cli/CMakeLists.txt, label cli), so the sanitizer job runs
it under ASan + UBSan too. Prints every failing case; exit 1 when there is one.
"""
from __future__ import annotations

import argparse
import copy
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BASE = ROOT / "tests" / "data" / "bench" / "quick-quiet.json"  # 9 repetitions, a fingerprint
# Bytes a terminal acts on: C0 controls but \n (line ends are ours), DEL, and the UTF-8 of
# the C1 controls U+0080..U+009F and of the bidirectional overrides.
RAW_CONTROL = re.compile(rb"[\x00-\x09\x0b-\x1f\x7f]|\xc2[\x80-\x9f]|\xe2\x80[\xaa-\xae]|\xe2\x81[\xa6-\xa9]")
HOSTILE_NAME = "bm/\x1b]0;owned\x07\x1b[2J|x`y\r\nfake | row |\u009b31m\u202eevil\tend"

failures: list[str] = []


def fail(case: str, why: str, r: subprocess.CompletedProcess | None = None) -> None:
    detail = ""
    if r is not None:
        detail = f"\n    exit {r.returncode}\n    stderr: {r.stderr[-600:]!r}\n    stdout: {r.stdout[-300:]!r}"
    failures.append(f"{case}: {why}{detail}")


def run(pb: str, args: list, timeout: float = 120) -> subprocess.CompletedProcess:
    r = subprocess.run([pb, *map(os.fsencode, args)], capture_output=True, timeout=timeout)
    return r


def expect_bad_input(case: str, r: subprocess.CompletedProcess, *needles: str) -> None:
    """Exit 2, one line on stderr starting 'pathbench: error: ', containing every needle."""
    err = r.stderr.decode("utf-8", "replace")
    lines = err.splitlines()
    if r.returncode != 2:
        return fail(case, "exit status is not 2", r)
    if len(lines) != 1 or not lines[0].startswith(("pathbench: error: ", "crosscheck.py: error: ")):
        return fail(case, "not one 'pathbench: error:' line", r)
    for n in needles:
        if n not in lines[0]:
            return fail(case, f"message does not name {n!r}", r)
    if RAW_CONTROL.search(r.stderr):
        fail(case, "a raw control character on stderr", r)


def expect_verdict(case: str, r: subprocess.CompletedProcess) -> None:
    """An odd but valid input: a verdict (0 or 1) or one bad-input line (2), nothing else."""
    if r.returncode in (0, 1):
        if RAW_CONTROL.search(r.stdout) or RAW_CONTROL.search(r.stderr):
            fail(case, "a raw control character in the output", r)
        return
    expect_bad_input(case, r)


# ---- compare ----------------------------------------------------------------------------

def mutate(base: dict, path: str, value, delete: bool = False) -> dict:
    """A copy of base with the field at dotted `path` ("context.fingerprint.machine_id",
    "benchmarks.*.name": every benchmark) set to value, or deleted."""
    out = copy.deepcopy(base)

    def walk(node, keys):
        k, rest = keys[0], keys[1:]
        targets = range(len(node)) if k == "*" else [int(k)] if isinstance(node, list) else [k]
        for t in targets:
            if rest:
                if isinstance(node, dict) and t not in node:
                    node[t] = {}  # e.g. a fingerprint's "gpu" section the fixture lacks
                walk(node[t], rest)
            elif delete:
                node.pop(t, None)
            else:
                node[t] = copy.deepcopy(value)

    walk(out, path.split("."))
    return out


def write(tmp: Path, name: str, data, raw: bool = False) -> Path:
    p = tmp / name
    p.write_text(data if raw else json.dumps(data))
    return p


def compare_cases(pb: str, tmp: Path) -> None:
    base = json.loads(BASE.read_text())
    good = write(tmp, "good.json", base)
    # A scalar of each other kind and a container; for numbers also the extremes.
    wrong_types = {"string": "5", "number": 5, "list": [1, "a"], "true": True, "huge int": 2**64 - 1,
                   "negative huge": -(2**63), "huge float": 1e308}
    # (field, acceptable types): every field compare reads, each given every other JSON type.
    fields = {
        "context.git_revision": {"string"}, "context.date_utc": {"string"}, "context.date": {"string"},
        "context.machine": {"string"}, "context.fingerprint": {"object"},
        "context.fingerprint.machine_id": {"string"}, "context.fingerprint.gpu": {"object"},
        "context.load_avg.0": {"number"},
        "context.fingerprint.gpu.gpu_id": {"string"}, "context.fingerprint.gpu.name": {"string"},
        "context.fingerprint.gpu.none": {"string"}, "context.run": {"object"},
        "context.run.cpu_per_wall": {"number"}, "context.num_cpus": {"number"},
        "context.load_avg": {"list"}, "context.caches": {"list"},
        "context.caches.0": {"object"}, "context.caches.0.level": {"number"}, "context.caches.0.type": {"string"},
        "benchmarks.*.name": {"string"}, "benchmarks.*.run_name": {"string"}, "benchmarks.*.run_type": {"string"},
        "benchmarks.*.real_time": {"number"}, "benchmarks.*.iterations": {"number"},
        "benchmarks.*.time_unit": {"string"}, "benchmarks.*.cpu_time": {"number"}, "benchmarks.*.label": {"string"},
        "benchmarks.*.error_occurred": {"true"}, "benchmarks.*.threads": {"number"},
        "benchmarks.*.process_cpu_seconds": {"number"},
    }
    # Per field: a wrong scalar and a container (numbers in the context: the extremes too), the file
    # as NEW; as BASE (and in Markdown) once.
    for field, ok in fields.items():
        shown = field.replace(".*", "[0]").replace(".0", "[0]")
        last = shown.split(".")[-1].split("[")[0]
        first = True
        for kind, value in wrong_types.items():
            extreme = kind in ("huge int", "negative huge", "huge float")
            if kind in ok or (extreme and ("number" not in ok or field.startswith("benchmarks"))):
                continue  # valid (a finite number where a time or count goes is a verdict, below)
            if kind == "true" or (kind == "number" and "string" not in ok):
                continue  # one wrong scalar and one container per field is enough to name it (time: CI)
            p = write(tmp, f"wrong-{kind.replace(' ', '-')}.json", mutate(base, field, value))
            expect_bad_input(f"compare {field} = {kind}", run(pb, ["compare", good, p]), p.name, last)
            if first:
                r = run(pb, ["compare", p, good, "--format", "markdown"])
                expect_bad_input(f"compare (as base) {field} = {kind}", r, p.name, last)
                first = False
    # Extreme but finite times: a verdict (or "no usable time"), never a failure.
    for value in (2**64 - 1, -(2**63), 1e308, 5e-324, 0):
        p = write(tmp, "extreme.json", mutate(base, "benchmarks.*.real_time", value))
        expect_verdict(f"compare real_time = {value}", run(pb, ["compare", good, p]))
        expect_verdict(f"compare (as base) real_time = {value}", run(pb, ["compare", p, good, "--format", "json"]))
    # Missing fields: a fingerprint names its machine; every benchmark has a name and a time.
    for field, needle in [("context.fingerprint.machine_id", "context.fingerprint.machine_id: missing"),
                          ("benchmarks.*.name", "benchmarks[0].name: missing"),
                          ("benchmarks.*.real_time", "benchmarks[0].real_time: missing"),
                          ("benchmarks.*.iterations", "benchmarks[0].iterations: missing")]:
        p = write(tmp, "missing.json", mutate(base, field, None, delete=True))
        for args in (["compare", good, p], ["compare", p, good, "--format", "json"]):
            expect_bad_input(f"compare without {field}", run(pb, args), "missing.json", needle)
    # Bare NaN / Infinity / 1e999 where a number goes (JSON has none: read as null or inf).
    text = BASE.read_text()
    for word in ("NaN", "-Infinity", "1e999", "-1e999"):
        bad = re.sub(r'"real_time": [0-9.e+-]+', f'"real_time": {word}', text)
        p = write(tmp, "nonfinite.json", bad, raw=True)
        # NaN and Infinity are Google Benchmark's (read as null: missing); 1e999 is not a double at all.
        expect_bad_input(f"compare real_time {word}", run(pb, ["compare", good, p]), "nonfinite.json",
                         "real_time" if "e999" not in word else "number overflow")
        bad = re.sub(r'"num_cpus": [0-9]+', f'"num_cpus": {word}', text)
        p = write(tmp, "nonfinite-cpus.json", bad, raw=True)
        expect_verdict(f"compare num_cpus {word}", run(pb, ["compare", good, p]))
    for name, data in [("context is a list", mutate(base, "context", [1])), ("benchmarks entry is a number",
                                                                             mutate(base, "benchmarks.0", 7)),
                       ("benchmarks is an object", mutate(base, "benchmarks", {"a": 1}))]:
        p = write(tmp, "shape.json", data)
        expect_bad_input(f"compare {name}", run(pb, ["compare", good, p]), "shape.json")
    hostile_names(pb, tmp, base)


def markdown_cells(line: str) -> int:
    """Cells of a Markdown table line: '|' not escaped by a backslash."""
    return len(re.findall(r"(?<!\\)\|", line)) - 1


def hostile_names(pb: str, tmp: Path, base: dict) -> None:
    data = mutate(base, "benchmarks.*.run_name", HOSTILE_NAME)
    data = mutate(data, "benchmarks.*.name", HOSTILE_NAME)
    for field in ("git_revision", "machine", "date_utc"):
        data = mutate(data, f"context.{field}", "x\x1b]8;;http://evil\x07\r\nforged: line|a")
    data = mutate(data, "context.fingerprint.machine_id", "id\x1b[31m|`")
    a = write(tmp, "names-a.json", data)
    other = mutate(data, "context.fingerprint.machine_id", "other\r\n\x1b[1A")  # a warning quotes both ids
    other = mutate(other, "benchmarks.0.label", "embree_layout=\x1b[5mquads")
    # A path from the command line with control characters and a byte that is not UTF-8.
    b = tmp / os.fsdecode(b"names-\x1b[31m\xff\xfe-b.json")
    b.write_text(json.dumps(other))
    for fmt in ("text", "markdown", "json"):
        r = run(pb, ["compare", a, b, "--format", fmt])
        case = f"compare --format {fmt} of hostile names"
        if r.returncode not in (0, 1):
            fail(case, "no verdict", r)
            continue
        if RAW_CONTROL.search(r.stdout) or RAW_CONTROL.search(r.stderr):
            fail(case, "a raw control character reached the output", r)
        out = r.stdout.decode("utf-8", "replace")
        if fmt == "markdown":
            rows = [line for line in out.splitlines() if line.startswith("|")]
            bad = [line for line in rows if markdown_cells(line) != 8]
            if len(rows) != 3 or bad:
                fail(case, f"the table has {len(rows)} lines, {len(bad)} of them without 8 cells: {bad[:2]}", r)
        if fmt == "text" and "fake" in out and not re.search(r"\\r\\nfake", out):
            fail(case, "the name's CR LF is not shown escaped", r)
        if fmt == "json":
            j = json.loads(r.stdout)
            if j["benchmarks"][0]["name"] != HOSTILE_NAME:
                fail(case, "JSON does not carry the name exactly", r)
    # --strict: the warnings, then the refusal, on stderr.
    r = run(pb, ["compare", a, b, "--strict"])
    last = r.stderr.decode("utf-8", "replace").splitlines()[-1:] or [""]
    if r.returncode != 2 or not last[0].startswith("pathbench: error: --strict"):
        fail("compare --strict of hostile names", "not refused with exit 2", r)
    if RAW_CONTROL.search(r.stderr):
        fail("compare --strict of hostile names", "a raw control character in the warnings", r)


# ---- render and bench sizes ---------------------------------------------------------------

def size_cases(pb: str, tmp: Path) -> None:
    out = tmp / "x.pfm"
    for args, needle in [
        (["--width", "2147483648", "--height", "1"], "more than the supported 268435456"),
        (["--width", "4294967295", "--height", "4294967295"], "more than the supported 268435456"),
        (["--width", "65536", "--height", "65536"], "--width/--height"),
        (["--width", "16385", "--height", "16384"], "--width/--height"),
        (["--width", "4096", "--height", "4096", "--spp", "4294967295"], "--spp: 4096x4096 pixels at 4294967295"),
        (["--width", "4096", "--height", "4096", "--spp", "16777217"], "more than the supported 281474976710656"),
        (["--width", "8", "--height", "8", "--strategy", "wavefront", "--paths-in-flight", "18446744073709551615"],
         "--paths-in-flight: 18446744073709551615 is more than the supported 4294967295"),
        (["--width", "4294967296", "--height", "1"], "--width"),  # beyond 32 bits: CLI11 refuses it
    ]:
        r = run(pb, ["render", "--quiet", "--out", out, *args])
        expect_bad_input(f"render {' '.join(args)}", r, needle)
        if out.exists():
            fail(f"render {' '.join(args)}", "wrote an image")
    r = run(pb, ["accuracy", "--quick", "--width", "2147483648", "--height", "1", "--out-dir", tmp / "acc"])
    expect_bad_input("accuracy --width 2147483648 --height 1", r, "--width/--height")


# ---- crosscheck ---------------------------------------------------------------------------

def crosscheck_cases(pb: str, tmp: Path) -> None:
    plain = tmp / "plain-file"
    plain.write_text("not a folder")
    tiny = {"--width": "8", "--height": "6", "--spp": "1", "--device": "cpu"}
    for args, needle in [
        (["--out-dir", plain], "--out-dir"),
        (["--out-dir", plain / "sub"], "--out-dir"),
        (["--spp", "4294967295", "--mitsuba-spp-factor", "4294967295"], "--spp x --mitsuba-spp-factor"),
        (["--spp", "65536", "--mitsuba-spp-factor", "65536"], "4294967296 samples per pixel for Mitsuba"),
        (["--width", "2147483648", "--height", "1"], "--width/--height"),
        (["--mitsuba-xml", tmp / "no-such.xml"], "no-such.xml: no such file"),
        (["--mitsuba-xml", tmp], "not a regular file"),
        (["--threads", "-1"], "--threads"),
    ]:
        out = tmp / "cc-out"
        shutil.rmtree(out, ignore_errors=True)
        given = dict(zip(args[::2], args[1::2]))
        full = [x for k, v in {**tiny, "--out-dir": out, **given}.items() for x in (k, v)]
        r = run(pb, ["crosscheck", "paper-cornell", *full])
        expect_bad_input(f"crosscheck {' '.join(map(str, args))}", r, needle)
        if out.exists():
            fail(f"crosscheck {' '.join(map(str, args))}", f"left {out}")
    if plain.read_text() != "not a folder":
        fail("crosscheck --out-dir FILE", "the file was changed")
    if subprocess.run([sys.executable, "-c", "import mitsuba"], capture_output=True).returncode != 0:
        print("note: Mitsuba 3 is not importable here: its crosscheck cases skipped")
        return
    # A Mitsuba scene `render` accepts, without an <integrator>: a verdict, not Mitsuba's
    # uncaught "No integrator specified" (exit 1, read as "different").
    formats = ROOT / "tests" / "data" / "scenes" / "formats"
    shutil.copy(formats / "cube.obj", tmp / "cube.obj")
    xml = (formats / "instanced.xml").read_text()
    (tmp / "no-integrator.xml").write_text(re.sub(r"<integrator.*?</integrator>", "", xml))
    out = tmp / "no-integrator"
    r = run(pb, ["crosscheck", tmp / "no-integrator.xml", "--spp", "1", "--mitsuba-spp-factor", "2", "--device", "cpu",
                 "--out-dir", out], timeout=300)
    if r.returncode not in (0, 1) or not (out / "verdict.json").is_file():
        fail("crosscheck of a scene without <integrator>", "no verdict", r)
    # Bad input found late (Mitsuba cannot read the reference, after pathbench rendered):
    # exit 2 and nothing of this run left, in a new --out-dir and in one that held a file.
    broken = tmp / "broken.xml"
    broken.write_text("<scene version='3.0.0'><shape type='nosuchplugin'/></scene>")
    kept = tmp / "existing"
    kept.mkdir()
    (kept / "keep.txt").write_text("mine")
    for out, before in ((tmp / "new" / "deeper", None), (kept, ["keep.txt"])):
        r = run(pb, ["crosscheck", "paper-cornell", *[x for kv in tiny.items() for x in kv], "--mitsuba-xml", broken,
                     "--out-dir", out], timeout=300)
        expect_bad_input(f"crosscheck --mitsuba-xml broken.xml --out-dir {out.name}", r, "broken.xml")
        left = sorted(p.name for p in out.iterdir()) if out.exists() else None
        if left != before or (before is None and (tmp / "new").exists()):
            fail(f"crosscheck --mitsuba-xml broken.xml --out-dir {out.name}", f"left {left} (expected {before})", r)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--pathbench", required=True)
    ap.add_argument("--surface", choices=["compare", "sizes", "crosscheck"], required=True)
    ap.add_argument("--tmp", type=Path, required=True)
    a = ap.parse_args()
    tmp = a.tmp / a.surface
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    {"compare": compare_cases, "sizes": size_cases, "crosscheck": crosscheck_cases}[a.surface](a.pathbench, tmp)
    for f in failures:
        print(f"FAIL {f}")
    print(f"hostile_cli {a.surface}: {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
