"""The `passthrough` elements of a spec -> passthrough.xacro, unchanged but for xacro escapes."""

from __future__ import annotations

from lxml import etree

from armcli.compiler.xmlfmt import literal, robot
from armcli.spec.passthrough import parse_element


def _escape(el: etree._Element) -> None:
    """Make every attribute and text a xacro literal, so `${...}` in copied XML stays text."""
    for node in el.iter():
        if node.tail:
            node.tail = literal(node.tail)
        if not isinstance(node.tag, str):
            continue  # comments and processing instructions are not expanded
        if node.text:
            node.text = literal(node.text)
        for key, value in node.attrib.items():
            node.set(key, literal(str(value)))


def copy_into(parent: etree._Element, elements: list[str]) -> None:
    """Append each passthrough element to `parent`, as xacro literals."""
    for text in elements:
        el = parse_element(text)
        _escape(el)
        el.tail = None
        parent.append(el)


def passthrough_tree(elements: list[str]) -> etree._Element:
    """The passthrough.xacro tree: each element copied in order."""
    root = robot()
    copy_into(root, elements)
    return root
