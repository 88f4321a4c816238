#!/usr/bin/env python3
"""Where a kernel's instructions go, from Nsight Compute's SASS source page.

Reads the CSV that `ncu -i REPORT --page source --csv --print-source sass` writes
(scripts/gpu_sass_profile.sh makes it) and prints, per unit of work (--per: e.g. the
launch's samples divided by 32, for warp instructions per warp of samples):
  - the executed warp instructions and the sampled warp stalls by opcode,
  - the hottest straight-line blocks (runs of instructions with one execution count),
    with their first instructions, so a block can be found in the disassembly.

  tools/sass_profile.py pixel-sass.csv[.gz] --per 2048 [--top 25]
"""
import argparse
import collections
import csv
import gzip
import io
import re
import sys


def read_rows(path):
    raw = gzip.open(path, "rt") if path.endswith(".gz") else open(path, newline="")
    rows = list(csv.reader(io.StringIO(raw.read())))
    for i, r in enumerate(rows):
        if "Instructions Executed" in r and "Source" in r:
            hdr = r
            body = rows[i + 1:]
            break
    else:
        sys.exit(f"{path}: no 'Instructions Executed' / 'Source' header (not an ncu source page CSV?)")
    col = {name: hdr.index(name) for name in ("Source", "Instructions Executed")}
    stall = hdr.index("Warp Stall Sampling (All Samples)") if "Warp Stall Sampling (All Samples)" in hdr else None
    out = []
    for r in body:
        if len(r) <= col["Instructions Executed"]:
            continue
        text = r[col["Source"]].strip()
        n = float(r[col["Instructions Executed"]] or 0)
        s = float(r[stall] or 0) if stall is not None else 0.0
        out.append((text, n, s))
    return out


def opcode(text):
    t = re.sub(r"^@!?U?P\w+\s+", "", text)  # drop a predicate guard
    return t.split()[0] if t else "?"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("--per", type=float, default=1.0, help="divide counts by this (units of work in the launch)")
    ap.add_argument("--top", type=int, default=25)
    a = ap.parse_args()
    rows = read_rows(a.csv)
    total = sum(n for _, n, _ in rows)
    stalls = sum(s for _, _, s in rows) or 1.0
    if total == 0:
        sys.exit(f"{a.csv}: no executed instructions")
    print(f"{len(rows)} SASS instructions; {total / a.per:.1f} executed warp instructions per unit "
          f"({total:.0f} in all), {stalls:.0f} stall samples")
    by_op, st_op = collections.Counter(), collections.Counter()
    for text, n, s in rows:
        by_op[opcode(text)] += n
        st_op[opcode(text)] += s
    print(f"\n{'opcode':24s} {'per unit':>9s} {'inst %':>7s} {'stall %':>8s}")
    for op, n in by_op.most_common(a.top):
        print(f"{op:24s} {n / a.per:9.1f} {n / total * 100:7.1f} {st_op[op] / stalls * 100:8.1f}")
    blocks, cur = [], None
    for i, (text, n, s) in enumerate(rows):
        if cur and cur["n"] == n:
            cur["end"] = i
            cur["stall"] += s
        else:
            cur = {"start": i, "end": i, "n": n, "stall": s, "first": text}
            blocks.append(cur)
    blocks.sort(key=lambda b: -(b["end"] - b["start"] + 1) * b["n"])
    print(f"\n{'block':>11s} {'len':>4s} {'x per unit':>10s} {'share':>6s} {'stall %':>8s}  first instruction")
    for b in blocks[:a.top]:
        length = b["end"] - b["start"] + 1
        print(f"{b['start']:5d}-{b['end']:5d} {length:4d} {b['n'] / a.per:10.3f} {length * b['n'] / total * 100:5.1f}% "
              f"{b['stall'] / stalls * 100:8.1f}  {b['first'][:60]}")


if __name__ == "__main__":
    main()
