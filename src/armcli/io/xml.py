"""Parsing an XML file a stranger wrote: one safe parser for URDF, SRDF and ROS package files.

Why one module: the URDF reader and the package checker each had their own parser set-up and
DOCTYPE test, and the checker's searched the bytes for `<!DOCTYPE` (refusing a comment that
names one, issue 42's lesson). Here the document must be UTF-8, its DOCTYPE is found in the
prolog (io/doctype.py), lxml runs without DTDs, entities or network, and the nesting depth
is capped: every refusal is one InputError naming the file and line.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from armcli.errors import InputError
from armcli.io.doctype import doctype_offset

if TYPE_CHECKING:
    from lxml import etree


def parse_xml(data: bytes, source: str, *, max_depth: int, kind: str = "") -> etree._Element:
    """XML bytes -> root element, refusing DOCTYPEs, non-UTF-8 text and deep nesting.

    `kind` names the format in the messages ("URDF" -> "... in URDF input").
    """
    from lxml import etree

    try:  # first: in UTF-16 the DOCTYPE test below would not see "<!DOCTYPE"
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        what = f"{kind} files are UTF-8" if kind else "XML input must be UTF-8"
        line = data.count(b"\n", 0, exc.start) + 1
        raise InputError(f"not UTF-8 text ({what})", file=source, line=line) from None
    at = doctype_offset(text)  # the prolog's: a comment that names one declares nothing
    if at is not None:
        where = f" in {kind} input" if kind else ""
        line = text.count("\n", 0, at) + 1
        raise InputError(
            f"DOCTYPE/entity declarations are not allowed{where}", file=source, line=line
        )
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
    )
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        if "Excessive depth" in str(exc.msg):  # libxml2's own cap (256) hit before ours
            deep = f"XML nested deeper than {max_depth} levels"
            raise InputError(deep, file=source, line=exc.lineno) from None
        raise InputError(f"not well-formed XML: {exc.msg}", file=source, line=exc.lineno) from None
    if root is None:
        raise InputError("empty XML document", file=source)
    _check_depth(root, source, max_depth)
    return root


def line_of(el: etree._Element) -> int | None:
    """An element's 1-based source line."""
    line = el.sourceline
    return line if isinstance(line, int) else None


def _check_depth(root: etree._Element, source: str, max_depth: int) -> None:
    stack = [(root, 1)]
    while stack:
        el, depth = stack.pop()
        if depth > max_depth:
            deep = f"XML nested deeper than {max_depth} levels"
            raise InputError(deep, file=source, line=line_of(el))
        stack.extend((c, depth + 1) for c in el)
