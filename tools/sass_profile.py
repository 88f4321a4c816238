#!/usr/bin/env python3
"""Where a kernel's instructions go, from Nsight Compute's SASS source page.

Reads the CSV that `ncu -i REPORT --page source --csv --print-source sass` writes
(scripts/device/gpu_sass_profile.sh makes it; plain or gzipped) and prints, per unit of work (--per:
e.g. the launch's samples divided by 32, for warp instructions per warp of samples):
  - the executed warp instructions and the sampled warp stalls by opcode,
  - the hottest straight-line blocks (runs of instructions with one execution count),
    with their first instruction, so a block can be found in the disassembly;
  - with --stalls N: the stall samples by reason, and the N instructions with the most
    stall samples, each with its two largest reasons (where a kernel waits, and on what:
    e.g. long_sb on the instruction that first uses a load's or an atomic's result).

  tools/sass_profile.py pixel-sass.csv[.gz] --per 2048 [--top 25] [--stalls 12]
"""
import argparse
import collections
import csv
import gzip
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

STALL_COLUMN = "Warp Stall Sampling (All Samples)"
REASON_PREFIX = "stall_"  # the per-reason sample columns (ncu names "stall_long_sb", ...)


@dataclass
class Instruction:
    text: str        # the SASS line, predicate guard included
    executed: float  # warp-level executions in the profiled launch
    stalls: float    # sampled warp stalls at this instruction (0 where not sampled)
    reasons: dict = field(default_factory=dict)  # {reason: samples}, nonzero ones only


@dataclass
class Block:
    start: int  # index of its first instruction
    end: int    # index of its last instruction
    executed: float
    stalls: float
    first: str

    @property
    def length(self):
        return self.end - self.start + 1

    @property
    def instructions(self):
        return self.length * self.executed


def read_instructions(path):
    """The SASS instructions of the CSV, in address order. Raises ValueError when the path
    is not a regular file (a device or FIFO would be read forever or wait for a writer) or
    has no 'Source' and 'Instructions Executed' header row (not a source page)."""
    if not Path(path).is_file():
        raise ValueError(f"{path}: not a regular file")
    opener = gzip.open if str(path).endswith(".gz") else open
    try:
        with opener(path, "rt", newline="") as raw:
            rows = list(csv.reader(raw))
    except (csv.Error, UnicodeDecodeError, gzip.BadGzipFile) as e:
        raise ValueError(f"{path}: not a CSV file ({e})") from e
    for i, r in enumerate(rows):
        if "Instructions Executed" in r and "Source" in r:
            hdr, body = r, rows[i + 1:]
            break
    else:
        raise ValueError(f"{path}: no 'Source' / 'Instructions Executed' header row "
                         "(not the CSV of ncu --page source --print-source sass?)")
    src, ex = hdr.index("Source"), hdr.index("Instructions Executed")
    st = hdr.index(STALL_COLUMN) if STALL_COLUMN in hdr else None
    # All samples per reason; ncu adds a "(Not Issued)" twin of each, left out here.
    reason_cols = [(i, h[len(REASON_PREFIX):]) for i, h in enumerate(hdr)
                   if h.startswith(REASON_PREFIX) and "Not Issued" not in h]
    out = []
    for r in body:
        if len(r) <= max(src, ex):
            continue
        try:
            stalls = float(r[st] or 0) if st is not None and len(r) > st else 0.0
            reasons = {name: float(r[i]) for i, name in reason_cols if i < len(r) and r[i] and float(r[i])}
            out.append(Instruction(r[src].strip(), float(r[ex] or 0), stalls, reasons))
        except ValueError as e:
            raise ValueError(f"{path}: a count that is not a number ({e})") from e
    return out


def opcode(text):
    """The opcode of a SASS line, without its predicate guard (`@!P0 BRA x` -> `BRA`)."""
    t = re.sub(r"^@!?U?P\w+\s+", "", text.strip())
    return t.split()[0] if t else "?"


def by_opcode(instructions):
    """{opcode: (executed, stalls)}, most executed first."""
    ex, st = collections.Counter(), collections.Counter()
    for ins in instructions:
        ex[opcode(ins.text)] += ins.executed
        st[opcode(ins.text)] += ins.stalls
    return {op: (n, st[op]) for op, n in ex.most_common()}


def hot_blocks(instructions):
    """Runs of consecutive instructions with one execution count, most instructions first."""
    blocks = []
    for i, ins in enumerate(instructions):
        if blocks and blocks[-1].executed == ins.executed and blocks[-1].end == i - 1:
            blocks[-1].end = i
            blocks[-1].stalls += ins.stalls
        else:
            blocks.append(Block(i, i, ins.executed, ins.stalls, ins.text))
    return sorted(blocks, key=lambda b: -b.instructions)


def report(instructions, per=1.0, top=25):
    total = sum(i.executed for i in instructions)
    if total == 0:
        raise ValueError("no executed instructions")
    stalls = sum(i.stalls for i in instructions) or 1.0
    lines = [f"{len(instructions)} SASS instructions; {total / per:.1f} executed warp instructions per unit "
             f"({total:.0f} in all), {stalls:.0f} stall samples", "",
             f"{'opcode':24s} {'per unit':>9s} {'inst %':>7s} {'stall %':>8s}"]
    for op, (n, s) in list(by_opcode(instructions).items())[:top]:
        lines.append(f"{op:24s} {n / per:9.1f} {n / total * 100:7.1f} {s / stalls * 100:8.1f}")
    lines += ["", f"{'block':>11s} {'len':>4s} {'x per unit':>10s} {'share':>6s} {'stall %':>8s}  first instruction"]
    for b in hot_blocks(instructions)[:top]:
        lines.append(f"{b.start:5d}-{b.end:5d} {b.length:4d} {b.executed / per:10.3f} "
                     f"{b.instructions / total * 100:5.1f}% {b.stalls / stalls * 100:8.1f}  {b.first[:60]}")
    return "\n".join(lines)


def stall_report(instructions, top=12):
    """The stall samples by reason, then the `top` instructions with the most samples (their
    index in address order, share, executions, text and two largest reasons)."""
    total = sum(i.stalls for i in instructions)
    if total == 0:
        raise ValueError("no stall samples (was the SourceCounters section collected?)")
    by_reason = collections.Counter()
    for ins in instructions:
        by_reason.update(ins.reasons)
    lines = [f"{total:.0f} stall samples; by reason: " +
             ", ".join(f"{r} {n / total * 100:.1f} %" for r, n in by_reason.most_common(8)), "",
             f"{'index':>6s} {'stall %':>7s} {'executed':>10s}  {'instruction':60s} reasons"]
    worst = sorted(range(len(instructions)), key=lambda k: -instructions[k].stalls)[:top]
    for k in sorted(worst):
        ins = instructions[k]
        if ins.stalls == 0:
            continue
        why = ", ".join(f"{r} {n:.0f}" for r, n in collections.Counter(ins.reasons).most_common(2))
        lines.append(f"{k:6d} {ins.stalls / total * 100:7.1f} {ins.executed:10.0f}  {ins.text[:60]:60s} {why}")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("--per", type=float, default=1.0, help="divide counts by this (units of work in the launch)")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--stalls", type=int, default=0, metavar="N",
                    help="also the stall samples by reason and the N most stalled instructions")
    a = ap.parse_args(argv)
    if not a.per > 0:
        ap.error("--per must be positive")
    if a.top < 1:
        ap.error("--top must be at least 1")
    if a.stalls < 0:
        ap.error("--stalls must not be negative")
    try:
        instructions = read_instructions(a.csv)
        print(report(instructions, a.per, a.top))
        if a.stalls:
            print()
            print(stall_report(instructions, a.stalls))
    except (OSError, ValueError) as e:
        print(f"sass_profile: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
