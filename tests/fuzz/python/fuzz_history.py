"""Fuzz target for the history's readers (tools/history): one input is a file `history record`
reads (bench JSON or a render report) or, with a first byte `r`, a run file of the text export
that `history rebuild` reads. Each input goes the whole way a real one goes: parse and validate,
store in a fresh database, write its run file and read it back, change points, the dashboard's
data and page, the terminal and Markdown tables.

A finding is anything but a clean refusal (store.UserError: what the CLI prints as one line with
exit 2): another exception, a run file that does not read back as the same run, a raw control
character in terminal or Markdown output, an inline script that could close its element, or an
input over -timeout / -rss_limit_mb.

  .venv/bin/python tests/fuzz/python/fuzz_history.py CORPUS_DIR SEEDS_DIR -max_total_time=60 \
      -dict=tests/fuzz/history.dict          (libFuzzer flags; atheris 3, tools/requirements.txt)
  .venv/bin/python tests/fuzz/python/fuzz_history.py --replay FILE_OR_DIR...   (no atheris needed)
  .venv/bin/python tests/fuzz/python/fuzz_history.py --mutate SECONDS SEEDS_DIR (no atheris: a
      seeded byte/token mutation loop, for a Python without atheris)

scripts/fuzz.sh history SECONDS runs it the way CI does.
"""
from __future__ import annotations

import os
import random
import re
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "tools"))

try:
    import atheris
except ImportError:  # --replay and --mutate work without it
    atheris = None

if atheris is not None and "--replay" not in sys.argv and "--mutate" not in sys.argv:
    with atheris.instrument_imports(include=["history"]):
        from history import changes, importer, report, runfile, store, text
else:
    from history import changes, importer, report, runfile, store, text

# git is not part of what is fuzzed (tests/python/test_history_hostile.py covers its arguments),
# and a process per input would make the fuzzer a hundred times slower.
importer._git = lambda *a, **k: None

TMP = tempfile.mkdtemp(prefix="fuzz-history-")
RAW_CONTROL = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


class Finding(AssertionError):
    pass


def _check_terminal(s: str, what: str, newline_ok: bool = True) -> None:
    if RAW_CONTROL.search(s) or (not newline_ok and "\n" in s):
        raise Finding(f"{what}: a raw control character reaches the terminal: {s!r:.200}")


def one_input(data: bytes) -> None:
    path = os.path.join(TMP, "input.json")
    with open(path, "wb") as f:
        f.write(data[1:] if data[:1] == b"r" else data)
    try:
        run = runfile.read_run(path) if data[:1] == b"r" else importer.parse(path)
    except store.UserError:
        return  # a clean refusal: exit 2 with one line
    # Past this point the run was accepted: every later refusal is a finding too (a run the
    # history took must store, export, read back, and show).
    try:
        follow(run, data)
    except store.UserError as e:
        raise Finding(f"an accepted run was refused later: {e}") from e


def follow(run: dict, data: bytes) -> None:
    _check_terminal(text.term(run["source"]) + text.term(run["machine_name"]) +
                    "".join(text.term(r["benchmark"]) for r in run["results"]), "names", newline_ok=False)
    db = store.connect(":memory:")
    try:
        importer.insert_all(db, [run], export_dir=os.path.join(TMP, "runs"))
        # Two more runs of the same series (other commits, values scaled by data's last byte),
        # so change points are computed on three points: Otava and the exact steps run too.
        factor = 1 + (data[-1] if data else 0) / 64
        for k, f in enumerate((factor, 1 / factor)):
            more = dict(run, run_key=f"{k + 1:064x}", commit=f"{k + 1:040x}", run_date=f"9999-12-3{k}T00:00:00+00:00",
                        commit_date=None, results=[dict(r, value=_times(r["value"], f)) for r in run["results"]])
            if not importer.recorded(db, more["run_key"]):
                importer.insert_all(db, [more])
        # The run file reads back as the same run.
        written = os.path.join(TMP, "runs", runfile.file_name(run))
        back = runfile.read_run(written)
        os.remove(written)
        for k in runfile.HEADER_KEYS:
            if back.get(k) != run.get(k) and not (k == "source" and not run.get(k)):
                raise Finding(f"run file round trip changed {k}: {run.get(k)!r:.100} -> {back.get(k)!r:.100}")
        if sorted(back["results"], key=_key) != sorted(run["results"], key=_key):
            raise Finding("run file round trip changed the results")
        found = changes.find(db)
        table, md = changes.format_table(found), changes.format_markdown(found)
        _check_terminal(table, "changes table")
        if found and table.count("\n") != len(found):
            raise Finding("the changes table has a line more or less than its changes")
        for line in md.split("\n")[2:]:
            _check_terminal(line, "markdown")
            if line.count("|") - line.count("\\|") != 7:
                raise Finding(f"a Markdown row has the wrong number of cells: {line!r:.200}")
        site = report.collect(db)
        page = report._page(site)
        blob = page.split('type="application/json">', 1)[1].rsplit("</script>", 2)[0]
        if re.search("[<>\u2028\u2029]", blob):
            raise Finding("the inline data holds a raw '<', '>' or U+2028/9")
    finally:
        db.close()


def _times(v, f):
    """v * f as the history could hold it (finite), else None."""
    if v is None:
        return None
    w = v * f
    return w if w == w and abs(w) != float("inf") else None


def _key(r):
    return (r["benchmark"], r["repetition"])


def replay(paths: list[str]) -> int:
    n = 0
    for p in paths:
        files = [os.path.join(p, f) for f in sorted(os.listdir(p))] if os.path.isdir(p) else [p]
        for f in files:
            with open(f, "rb") as fh:
                one_input(fh.read())
            n += 1
    print(f"replayed {n} inputs: no finding")
    return 0


TOKENS = [b"{", b"}", b"[", b"]", b",", b":", b'"', b"null", b"true", b"1e999", b"-1e999", b"NaN", b"Infinity",
          b"9223372036854775808", b"18446744073709551616", b"-1", b"0", b"\\u2028", b"\\ud800", b"\\u001b",
          b'"--output=x"', b'"9999-12-31T23:59:59-01:00"', b'"10000-01-01"', b'"a|b\\nc"', b"<!--<script>",
          b"</script>", b'"git_revision"', b'"benchmarks"', b'"context"', b'"real_time"', b'"time_unit"',
          b'"repetition_index"', b'"iterations"', b'"run_name"', b'"fingerprint"', b'"date"', b'"commit_seq"']


def mutate_loop(seconds: float, seed_dirs: list[str], seed: int = 1) -> int:
    """Without atheris: random byte edits and JSON-token splices of the seeds, for `seconds`."""
    rng = random.Random(seed)
    seeds = []
    for d in seed_dirs:
        for f in sorted(os.listdir(d)):
            with open(os.path.join(d, f), "rb") as fh:
                seeds.append(fh.read())
    end, n = time.monotonic() + seconds, 0
    while time.monotonic() < end:
        b = bytearray(rng.choice(seeds))
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(len(b) + 1)
            op = rng.random()
            if op < 0.3 and b:
                b[min(i, len(b) - 1)] = rng.randrange(256)
            elif op < 0.5:
                del b[i:i + rng.randint(1, 16)]
            else:
                b[i:i] = rng.choice(TOKENS)
        try:
            one_input(bytes(b))
        except Exception:
            crash = os.path.join(TMP, f"crash-{n}")
            with open(crash, "wb") as fh:
                fh.write(b)
            print(f"finding after {n} executions; input written to {crash}", file=sys.stderr)
            raise
        n += 1
    print(f"mutate: {n} executions in {seconds:.0f} s, no finding")
    return 0


def main() -> int:
    if "--replay" in sys.argv:
        return replay([a for a in sys.argv[1:] if a != "--replay"])
    if "--mutate" in sys.argv:
        i = sys.argv.index("--mutate")
        return mutate_loop(float(sys.argv[i + 1]), sys.argv[i + 2:])
    if atheris is None:
        print("fuzz_history: atheris is not installed (pip install -r tools/requirements.txt); "
              "use --mutate SECONDS SEEDS_DIR", file=sys.stderr)
        return 2
    atheris.Setup(sys.argv, one_input)
    atheris.Fuzz()
    return 0


if __name__ == "__main__":
    sys.exit(main())
