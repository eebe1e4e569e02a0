"""Whether an XML document declares a DOCTYPE: read from its prolog, not searched for.

DOCTYPE and entity declarations are refused in every XML input (billion laughs, external
entities), before any parser sees them. Searching the text for `<!DOCTYPE` also refused
documents that merely mention it in a comment: armcli's own generated xacro and URDF
files, whose header comment names the spec file, so a spec named
`r--><!DOCTYPE robot [...]><!--.yaml` no longer built (issue 42). A DOCTYPE can only
stand in the prolog, before the root element, and entities can only be declared inside
it (anywhere else `<!ENTITY` is a syntax error the parser reports), so the prolog (the
XML declaration, processing instructions, comments, white space) is read token by token
up to the root element: nothing is parsed, nothing is expanded.
"""

from __future__ import annotations

_SPACE = " \t\r\n"


def doctype_offset(text: str) -> int | None:
    """Where the document's DOCTYPE starts (an index of `text`), or None when it has none."""
    i = 1 if text.startswith("\ufeff") else 0
    while i < len(text):
        if text[i] in _SPACE:
            i += 1
        elif text.startswith("<?", i):  # the XML declaration or a processing instruction
            end = text.find("?>", i + 2)
            i = len(text) if end < 0 else end + 2
        elif text.startswith("<!--", i):
            end = text.find("-->", i + 4)
            i = len(text) if end < 0 else end + 3
        elif text.startswith("<!DOCTYPE", i):
            return i
        else:
            return None  # the root element: the prolog is over
    return None


def declares_doctype(text: str) -> bool:
    """Whether the XML document `text` has a DOCTYPE (and so may declare entities)."""
    return doctype_offset(text) is not None
