"""The one float formatter and XML serialiser shared by every writer.

Floats use Python's shortest round-trip repr, so values survive a write/read
cycle exactly and the same spec always gives the same bytes.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from lxml import etree

XACRO_NS = "http://www.ros.org/wiki/xacro"


def fmt(x: float) -> str:
    """Shortest exact text of a float; integers print without a trailing `.0`, -0 as 0."""
    v = float(x)
    if v == 0.0:
        return "0"
    if v.is_integer() and abs(v) < 1e15:
        return str(int(v))
    return repr(v)


def vec(values: Iterable[float]) -> str:
    """Space-separated `fmt` of each value, as URDF writes vectors (xyz, rpy, rgba)."""
    return " ".join(fmt(v) for v in values)


# Characters XML 1.0 does not allow anywhere, not even in a comment.
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff\ud800-\udfff]")


def comment_text(text: str) -> str:
    """`text` made safe inside `<!-- ... -->`, whatever names it holds.

    A space goes between consecutive hyphens (a comment may not hold `--`, so a name
    with `-->` cannot end the comment and inject markup); characters XML forbids are
    written as backslash-x escapes.
    """
    text = _NOT_XML.sub(lambda m: f"\\x{ord(m.group()):02x}", text)
    return re.sub(r"-(?=-)", "- ", text)


def to_bytes(root: etree._Element, *, header_comment: str | None = None) -> bytes:
    """Serialise with an XML declaration, two-space indentation and a trailing newline.

    The header comment goes through `comment_text`; " -->" closes it, so it never ends
    in "-" either.
    """
    etree.indent(root, space="  ")
    body = etree.tostring(root, encoding="unicode")
    out = '<?xml version="1.0"?>\n'
    if header_comment:
        out += f"<!-- {comment_text(header_comment)} -->\n"
    return (out + body + "\n").encode("utf-8")


_XACRO_SUBST = re.compile(r"(\$+)(?=[({])")


def literal(text: str) -> str:
    """`text` as a xacro literal: `${`/`$(` gain one `$`, which xacro removes again.

    For user text (mesh URIs, material names, copied XML) that must not be read as a
    xacro expression or substitution.
    """
    return _XACRO_SUBST.sub(r"$\1", text)


def robot(name: str | None = None) -> etree._Element:
    """An empty `<robot>` with the xacro namespace (named for top-level files)."""
    attrs = {"name": name} if name else {}
    return etree.Element("robot", attrs, nsmap={"xacro": XACRO_NS})


def sub(parent: etree._Element, tag: str, **attrs: str) -> etree._Element:
    """Append `<tag attrs/>` to `parent` and return it."""
    return etree.SubElement(parent, tag, attrs)
