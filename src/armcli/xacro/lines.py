"""Where each element of a xacro expansion was written: file, line and the macro calls.

`check` reads the expanded document, so its findings carry lines of that document,
which nobody can open. While xacro.safe expands a file, each element it parses is
tagged with its own file and line (an attribute xacro copies with the element
through macro bodies, blocks and conditionals, never evaluates and never sees as a
parameter); each macro call appends its own position to the elements it produced.
Before the document is written the tags are taken out again, so the output is
byte for byte xacro's, and the expanded line of every element is paired with its
origin: the line in the file that defines it (an included file's own line), and
the calls that brought it there, innermost first.

Elements xacro itself interprets (`xacro:property`, `xacro:if`, ...) are not tagged:
xacro would warn about an unknown attribute; they produce no URDF element.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from lxml import etree

MAX_TAG_LINES = 50  # a start tag spread over more lines keeps the line libxml2 gives
SRC = "armcli-src"  # the tag's attribute name (no xacro file uses it)
KEYWORDS = frozenset(
    {"macro", "property", "include", "if", "unless", "arg", "insert_block", "attribute"}
)


@dataclass(frozen=True)
class Origin:
    """Where an element of a xacro expansion was written [file, 1-based line] (xacro.lines)."""

    file: str
    line: int
    calls: tuple[tuple[str, int], ...] = ()  # macro calls that produced it, innermost first


def _elements(node: Any) -> Iterator[Any]:
    """A minidom node's elements, itself first, in document order."""
    if node.nodeType == node.ELEMENT_NODE:
        yield node
    for child in node.childNodes:
        yield from _elements(child)


def _tagged(tag: str) -> bool:
    """Whether an element gets a position: URDF elements and macro calls, not xacro's own."""
    return not tag.startswith("xacro:") or tag[6:] not in KEYWORDS


def annotate(doc: Any, text: str, file: int) -> None:
    """Tag every element of the minidom `doc` parsed from `text` with `file:line`.

    The lines come from lxml's parse of the same text (minidom keeps none); both see the
    same elements in the same order, and nothing is tagged if they do not agree.
    """
    try:
        root = etree.fromstring(
            text.encode("utf-8"), etree.XMLParser(resolve_entities=False, no_network=True)
        )
    except etree.XMLSyntaxError:
        return  # minidom parsed it; a disagreement costs only the positions
    lines = [el.sourceline for el in root.iter() if isinstance(el.tag, str)]
    nodes = list(_elements(doc.documentElement))
    if len(lines) != len(nodes):
        return
    rows = text.splitlines()
    for node, line in zip(nodes, lines, strict=True):
        if isinstance(line, int) and _tagged(node.tagName):
            node.setAttribute(SRC, f"{file}:{_start(rows, line, node.tagName)}")


def _start(rows: Sequence[str], line: int, tag: str) -> int:
    """The line a start tag begins on (libxml2 gives the one it ends on).

    `<inertia ixx=...` written over three lines is reported at the third.
    """
    for k in range(line, max(line - MAX_TAG_LINES, 0), -1):
        if k <= len(rows) and f"<{tag}" in rows[k - 1]:
            return k
    return line


def expand_call(node: Any, call: Callable[[], Any]) -> Any:
    """Run xacro's macro call on `node`, then add the call's position to what it produced.

    The call's own tag is removed first: xacro would take it for a macro parameter.
    """
    site = ""
    if node.tagName.startswith("xacro:") and node.hasAttribute(SRC):
        site = node.getAttribute(SRC)
        node.removeAttribute(SRC)
    parent, before, after = node.parentNode, node.previousSibling, node.nextSibling
    done = call()
    if not (done and site and parent is not None):
        return done
    cur = before.nextSibling if before is not None else parent.firstChild
    while cur is not None and cur is not after:
        for el in _elements(cur):
            own = el.getAttribute(SRC) if el.hasAttribute(SRC) else ""
            el.setAttribute(SRC, f"{own};{site.split(';')[0]}")
        cur = cur.nextSibling
    return done


def collect(doc: Any) -> list[str]:
    """Every element's tag in document order ("" when untagged), removed from the document."""
    out = []
    for el in _elements(doc.documentElement):
        out.append(el.getAttribute(SRC) if el.hasAttribute(SRC) else "")
        if el.hasAttribute(SRC):
            el.removeAttribute(SRC)
    return out


def source_map(expanded: bytes, tags: Sequence[str], files: Sequence[str]) -> str:
    """`expanded_line=file:line;file:line|...` for each tagged element's first line.

    `tags` are `collect`'s, in the document order of `expanded` (the text written from
    that document); `files` name the indices. Empty when they do not pair up.
    """
    try:
        root = etree.fromstring(expanded, etree.XMLParser(resolve_entities=False, huge_tree=True))
    except etree.XMLSyntaxError:
        return ""
    lines = [el.sourceline for el in root.iter() if isinstance(el.tag, str)]
    if len(lines) != len(tags):
        return ""
    seen: set[int] = set()
    out = []
    for line, tag in zip(lines, tags, strict=True):
        if not tag or not isinstance(line, int) or line in seen or tag.startswith(";"):
            continue
        seen.add(line)
        out.append(f"{line}={tag}")
    head = json.dumps(list(files))  # one line whatever the names hold (a newline: issue 42)
    return head + "\n\n" + "|".join(out)


def parse_map(text: str) -> dict[int, Origin]:
    """`source_map`'s text -> expanded line -> Origin (empty for an empty or bad map)."""
    head, sep, body = text.partition("\n\n")
    if not sep:
        return {}
    try:
        files = json.loads(head)
    except ValueError:
        return {}
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return {}
    out: dict[int, Origin] = {}
    for item in filter(None, body.split("|")):
        try:
            key, _, tag = item.partition("=")
            places = [p.split(":") for p in tag.split(";")]
            where = [(files[int(f)], int(n)) for f, n in places]
            out[int(key)] = Origin(where[0][0], where[0][1], tuple(where[1:]))
        except (ValueError, IndexError):
            continue  # a malformed entry: that element keeps its expanded line
    return out
