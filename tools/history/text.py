"""Text the history shows: every name comes from a file someone else wrote (benchmark names,
machine names, file names, commits), so none reaches a terminal, a Markdown table or a page raw.

- term(): for terminal lines. C0 and C1 control characters (ESC and so OSC/CSI sequences, CR, LF,
  TAB, BEL, NUL...), DEL, the Unicode line and paragraph separators, bidirectional overrides and
  isolates, and lone surrogates are written as \\xNN / \\uNNNN, and a backslash as \\\\, so a name
  can neither move the cursor, retitle the window, nor forge or hide a line of the table.
- md_cell(): term() plus `|` as `\\|`, for a cell of a Markdown table.
- script_json(): JSON to put inside an HTML <script> element (no `<`, `>`, `&`, U+2028/9 raw).
"""
from __future__ import annotations

import json
import re

# C0, DEL, C1; U+2028/9; bidi embeddings/overrides (U+202A-E) and isolates (U+2066-9); LRM/RLM/ALM;
# lone surrogates; the backslash itself so an escape cannot be forged either.
_UNSAFE = re.compile("[\\\\\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028\u2029\u202a-\u202e\u2066-\u2069"
                     "\ud800-\udfff]")


def _escape(m: re.Match) -> str:
    c = m.group()
    if c == "\\":
        return "\\\\"
    o = ord(c)
    return f"\\x{o:02x}" if o < 0x100 else f"\\u{o:04x}"


def term(s) -> str:
    return _UNSAFE.sub(_escape, str(s))


def md_cell(s) -> str:
    return term(s).replace("|", "\\|")


def script_json(data) -> str:
    """json.dumps for inline <script> data: `<` `>` `&` and U+2028/9 as \\u escapes, so neither
    `</script>` nor `<!--` (which puts the HTML parser in its escaped states) can end or change the
    element, and the text is JSON and JavaScript alike."""
    s = json.dumps(data, allow_nan=False)  # ensure_ascii: U+2028/9 and surrogates escaped already
    for c in "<>&":
        s = s.replace(c, f"\\u{ord(c):04x}")
    return s
