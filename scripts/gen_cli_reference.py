#!/usr/bin/env python3
"""docs/reference.md's "Command line" section, generated from the binary's own --help.

  scripts/gen_cli_reference.py [--pathbench build/bin/pathbench] --write docs/reference.md
  scripts/gen_cli_reference.py --check docs/reference.md     exit 1 when the section is stale
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

from generated_block import update

ROOT = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- cli-reference:begin -->", "<!-- cli-reference:end -->"
# `history` hands over to tools/history: its sub-subcommands each have a --help.
HISTORY_SUBS = ("record", "rebuild", "changes", "report", "instructions", "backfill")


def helptext(binary: str, args: list[str]) -> str | None:
    env = dict(os.environ, COLUMNS="100", LC_ALL="C")
    p = subprocess.run([binary, *args, "--help"], capture_output=True, text=True, env=env, cwd=ROOT, timeout=60)
    if p.returncode != 0:
        return None
    # Paths of the machine that generated it never belong in the page.
    return p.stdout.replace(binary, "pathbench").replace(str(ROOT), "<source>").rstrip()


def subcommands(top: str) -> list[str]:
    m = re.search(r"^SUBCOMMANDS:\n((?:[ \t]+\S.*\n?)+)", top, flags=re.M | re.I)
    return [line.split()[0] for line in m.group(1).splitlines() if line.strip()] if m else []


def block(binary: str) -> str:
    top = helptext(binary, [])
    if top is None:
        raise SystemExit(f"gen_cli_reference: {binary} --help failed")
    parts = [BEGIN, "", "### pathbench", "", "```text", top, "```"]
    for sub in subcommands(top):
        text = helptext(binary, [sub])
        if text is None:
            continue
        parts += ["", f"### pathbench {sub}", "", "```text", text, "```"]
        if sub == "history":
            for hs in HISTORY_SUBS:
                t = helptext(binary, [sub, hs])
                if t is not None:
                    parts += ["", f"#### pathbench history {hs}", "", "```text", t, "```"]
    parts += ["", END]
    return "\n".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pathbench", default=str(ROOT / "build" / "bin" / "pathbench"))
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--write", type=Path)
    g.add_argument("--check", type=Path)
    a = ap.parse_args(argv)
    page = a.write or a.check
    return update(page, BEGIN, END, block(a.pathbench), check=bool(a.check), tool="gen_cli_reference",
                  remedy=f"scripts/gen_cli_reference.py --write {page}")

if __name__ == "__main__":
    sys.exit(main())
