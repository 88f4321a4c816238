"""A generated block of a Markdown page, between a begin and an end marker: rewrite it, or
check that it is current. Shared by scripts/results_glance.py and scripts/gen_cli_reference.py."""
from __future__ import annotations

import sys
from pathlib import Path


def update(page: Path, begin: str, end: str, new: str, *, check: bool, tool: str, remedy: str) -> int:
    """0 written or current; 1 stale (check); 2 no markers. `new` includes both markers."""
    text = page.read_text()
    if begin not in text or end not in text:
        print(f"{tool}: {page}: no {begin} ... {end} markers", file=sys.stderr)
        return 2
    current = text[text.index(begin):text.index(end) + len(end)]
    if check:
        if current != new:
            print(f"{tool}: {page}: the generated block is stale; run {remedy}", file=sys.stderr)
            return 1
        return 0
    page.write_text(text.replace(current, new))
    return 0
