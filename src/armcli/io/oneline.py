"""One-line text: control characters in names and values shown as escapes, never emitted.

Every line armcli prints may be read by a machine: GitHub Actions reads workflow
commands (`::add-mask::`, `::error::`) from stdout and stderr, at the start of any
line. A file name or URDF value holding a newline (or a carriage return, or a
terminal escape sequence) would start a line of its own choosing, so names and
messages are passed through `one_line` before they reach a stream.
"""

from __future__ import annotations

_NAMED = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}
# C0 controls, DEL, C1 controls and the Unicode line and paragraph separators
_CONTROLS = [*range(0x00, 0x20), 0x7F, *range(0x80, 0xA0), 0x2028, 0x2029]
_TABLE = {c: _NAMED.get(chr(c), f"\\x{c:02x}" if c < 0x100 else f"\\u{c:04x}") for c in _CONTROLS}


def one_line(text: str) -> str:
    """`text` with every control character and line separator written as an escape."""
    return text.translate(_TABLE)
