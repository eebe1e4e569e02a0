"""URDF elements the spec does not type, kept verbatim (`passthrough`).

`armcli import` puts here what it found in a URDF but cannot express as spec fields
(transmissions, Gazebo tags other than colours, friction and the course's plugins,
vendor extensions), so that building the spec gives the same URDF back. Each entry
is one XML element, parsed without DTDs, entities or network access.

Data never becomes xacro (issue 27): xacro acts on the literal tag `xacro:include`
whatever namespace the prefix is bound to, and an element of the xacro namespace may
be written under any prefix, so an element or attribute is refused when its namespace
URI is a xacro one or its prefix is `xacro`, and so is a comment that switches on
xacro's comment evaluation. `${`/`$(` in text stay text (compiler.passthrough escapes
them).
"""

from __future__ import annotations

from typing import Annotated

from lxml import etree
from pydantic import AfterValidator, Field

from armcli.spec.xacro_names import xacro_use

MAX_PASSTHROUGH_CHARS = 200_000
TYPED_TAGS = ("link", "joint", "robot", "material")  # spec fields hold these
_PARSER = etree.XMLParser(
    resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False, remove_comments=False
)


def parse_element(text: str) -> etree._Element:
    """The one XML element `text` holds; ValueError if it is not exactly one."""
    try:
        el = etree.fromstring(text.encode("utf-8"), _PARSER)
    except etree.XMLSyntaxError as exc:
        raise ValueError(f"not one XML element: {exc}") from None
    tag = el.tag if isinstance(el.tag, str) else ""
    if tag in TYPED_TAGS:
        raise ValueError(f"<{tag}> is a spec field, not passthrough")
    return el


def _valid(text: str) -> str:
    el = parse_element(text)
    used = xacro_use(el)
    if used is not None:
        raise ValueError(
            f"{used}; passthrough XML is copied as data and may hold no xacro "
            "(a xacro include or macro would run when the spec is built)"
        )
    return text


PassthroughElement = Annotated[str, Field(max_length=MAX_PASSTHROUGH_CHARS), AfterValidator(_valid)]
