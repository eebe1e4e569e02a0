r"""One-line text: control characters in names and values shown as escapes, never emitted.

Every line armcli prints may be read by a machine: GitHub Actions reads workflow
commands (`::add-mask::`, `::error::`) from stdout and stderr, at the start of any
line. A file name or URDF value holding a newline (or a carriage return, or a
terminal escape sequence) would start a line of its own choosing, so names and
messages are passed through `one_line` before they reach a stream.

A file name that is not UTF-8 (reached by a glob include, say) arrives as Python's
surrogate escapes; written out they are the raw bytes, which no UTF-8 reader (a CI log,
a SARIF file) accepts. They are shown as `\xff`, the byte they stand for (issue 42).
"""

from __future__ import annotations

_NAMED = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}
# C0 controls, DEL, C1 controls and the Unicode line and paragraph separators
_CONTROLS = [*range(0x00, 0x20), 0x7F, *range(0x80, 0xA0), 0x2028, 0x2029]
_TABLE = {c: _NAMED.get(chr(c), f"\\x{c:02x}" if c < 0x100 else f"\\u{c:04x}") for c in _CONTROLS}
_UNDECODABLE = {c: f"\\x{c - 0xDC00:02x}" for c in range(0xDC80, 0xDD00)}  # surrogateescape
_TABLE.update(_UNDECODABLE)


def one_line(text: str) -> str:
    """`text` with every control character, line separator and undecodable byte escaped."""
    return text.translate(_TABLE)


def decodable(text: str) -> str:
    r"""`text` with the bytes of a non-UTF-8 file name (surrogate escapes) shown as `\xff`."""
    return text.translate(_UNDECODABLE)
