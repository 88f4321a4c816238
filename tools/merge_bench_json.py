#!/usr/bin/env python3
"""Merge Google Benchmark JSON files written by parts of one preset's run into one file.

A preset whose GPU rows take longer than one device call runs in parts
(scripts/device/gpu_bench_scaling.sh, one --benchmark_filter each); this joins them:

    python3 tools/merge_bench_json.py OUT.json PART.json [PART.json ...]

The parts must come from the same source commit, machine and GPU, and no benchmark may be in
two parts. The merged file keeps the first part's context, its benchmarks in the parts' order,
the union of the parts' film hashes with film_hash recomputed over them as pathbench-bench
computes it (bench/bench_context.cpp), and a "merged_from" list with each part's date and load.
Bad input (not a regular file, over 64 MiB, not a benchmark JSON, parts that do not match) exits
2 with one line on stderr and writes nothing; the output goes into place whole or not at all
(a temporary file of its own beside it, renamed), so two merges into one path never mix.
"""
import json
import os
import sys

from atomic_file import write_text_atomically
from history.fields import RecordError, read_bytes  # the history importer's reader: regular files, a size limit

MAX_PART_BYTES = 64 << 20  # benchmark JSON's limit (docs/reference.md)

# Context fields that must agree: the parts describe one build on one machine.
SAME = ("git_revision", "machine_id", "gpu_name", "gpu_driver", "pathbench_preset", "build_type")


def fnv1a64(text):
    """Standard FNV-1a 64, as bench/bench_context.cpp hashes the films. (Not tools/machine.py's
    fnv1a64_hex, whose offset basis differs: machine ids are another hash.)"""
    h = 0xCBF29CE484222325
    for byte in text.encode():
        h = ((h ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def load(path):
    try:
        doc = json.loads(read_bytes(path, MAX_PART_BYTES).decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise ValueError(f"{path}: {e}") from None
    except RecordError as e:  # not a regular file, too large, unreadable
        raise ValueError(str(e)) from None
    if not isinstance(doc, dict) or not isinstance(doc.get("context"), dict) or \
            not isinstance(doc.get("benchmarks"), list):
        raise ValueError(f"{path}: not a Google Benchmark JSON (no context object and benchmarks list)")
    if not all(isinstance(b, dict) and isinstance(b.get("name"), str) for b in doc["benchmarks"]):
        raise ValueError(f"{path}: a benchmark without a name")
    return doc


def merge(docs, paths):
    first = docs[0]["context"]
    for doc, path in zip(docs[1:], paths[1:]):
        for key in SAME:
            if doc["context"].get(key) != first.get(key):
                raise ValueError(f"{path}: {key} {doc['context'].get(key)!r} differs from "
                                 f"{paths[0]}'s {first.get(key)!r}")
    seen, benchmarks, hashes = {}, [], {}
    for doc, path in zip(docs, paths):
        for b in doc["benchmarks"]:
            if b["name"] in seen and seen[b["name"]] != path:
                raise ValueError(f"{path}: {b['name']} is in {seen[b['name']]} too")
            seen[b["name"]] = path
            benchmarks.append(b)
        part_hashes = doc["context"].get("film_hashes") or {}
        if not isinstance(part_hashes, dict):
            raise ValueError(f"{path}: film_hashes is not an object")
        hashes.update(part_hashes)
    context = dict(first)
    if hashes:
        hashes = dict(sorted(hashes.items()))  # as std::map orders them
        context["film_hashes"] = hashes
        context["film_hash"] = "fnv1a64:{:016x}".format(
            fnv1a64("".join(f"{name}={h}\n" for name, h in hashes.items())))
    context["merged_from"] = [
        {"file": os.path.basename(p), "date": d["context"].get("date"), "load_avg": d["context"].get("load_avg"),
         "benchmarks": len(d["benchmarks"])} for d, p in zip(docs, paths)]
    return {"context": context, "benchmarks": benchmarks}


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    usage = "usage: tools/merge_bench_json.py OUT.json PART.json [PART.json ...]"
    if argv and argv[0] in ("-h", "--help"):
        print(usage)
        return 0
    if len(argv) < 2:
        print(usage, file=sys.stderr)
        return 2
    out, parts = argv[0], argv[1:]
    try:
        merged = merge([load(p) for p in parts], parts)
    except ValueError as e:
        print(f"merge_bench_json: {e}", file=sys.stderr)
        return 2
    try:
        # As Google Benchmark writes it: NaN allowed, since its counters may hold one.
        write_text_atomically(out, json.dumps(merged, indent=2) + "\n")
    except OSError as e:
        print(f"merge_bench_json: {out}: {e.strerror or e}", file=sys.stderr)
        return 2
    print(f"{out}: {len(merged['benchmarks'])} benchmarks from {len(parts)} parts")
    return 0


if __name__ == "__main__":
    sys.exit(main())
