"""What xacro would act on in a piece of XML: the one test for "data never becomes xacro".

xacro (a minidom program) matches literal tag names: `<xacro:include>` is an include
whatever URI the `xacro` prefix is bound to, and lxml may write an element of the xacro
namespace under another prefix (or the default one). So XML counts as xacro when an
element or attribute has a xacro namespace URI (any prefix) or the `xacro` prefix (any
URI), or a comment names `xacro:` (`xacro:eval-comments` makes xacro evaluate comments).
Used by spec passthrough (refused) and the URDF reader (the file is a xacro).
Plain lxml, no pydantic: the URDF reader imports it.
"""

from __future__ import annotations

import re

from lxml import etree

XACRO_PREFIX = "xacro"
# www.ros.org/wiki/xacro, ros.org/wiki/xacro, wiki.ros.org/xacro (all occur); any URI naming
# xacro is treated as one, since refusing a vendor's odd URI costs less than missing one
_XACRO_URI = re.compile(r"xacro", re.IGNORECASE)
_SUBSTITUTION = re.compile(r"\$[({]")  # `${...}` and `$(...)`: escaped in text, refused in URIs


def is_xacro_uri(uri: str | None) -> bool:
    """Whether a namespace URI is xacro's (any spelling that names xacro)."""
    return uri is not None and _XACRO_URI.search(uri) is not None


def _prefixes(el: etree._Element, uri: str) -> list[str]:
    return [str(p) for p, u in el.nsmap.items() if u == uri and p is not None]


def xacro_use(el: etree._Element) -> str | None:
    """What in `el`'s tree xacro would act on (a description), or None."""
    for node in el.iter():
        if not isinstance(node.tag, str):
            text = str(node.text or "")
            if isinstance(node, etree._Comment) and "xacro:" in text:
                return "a comment naming xacro: (xacro:eval-comments evaluates comments)"
            continue
        name = etree.QName(node)
        for uri in node.nsmap.values():  # xacro evaluates xmlns declarations as attributes
            if _SUBSTITUTION.search(str(uri)):
                return f"namespace URI {uri!r} of <{name.localname}> holds a xacro substitution"
        if is_xacro_uri(name.namespace) or node.prefix == XACRO_PREFIX:
            return f"element <{node.prefix + ':' if node.prefix else ''}{name.localname}> is xacro"
        for key in node.attrib:
            aname = etree.QName(key)
            if aname.namespace is None:
                continue
            if is_xacro_uri(aname.namespace) or XACRO_PREFIX in _prefixes(node, aname.namespace):
                return (
                    f"attribute {aname.localname!r} of <{name.localname}> is in the xacro namespace"
                )
    return None
