"""XML that GitHub Actions never reads as a workflow command, and parses as it did.

GitHub reads `::error::`, `::add-mask::` ... at the start of any line of a step's output
(leading white space trimmed). `armcli expand` prints a document xacro's way, and a text
node holding `&#10;::error::...` came out as a line of its own (issue 42). Only the line
breaks that such a line follows are rewritten, each as what XML reads the same way:

- in text: the character reference (`&#10;`, `&#13;`);
- in an attribute value: a space (XML normalises a raw line break there to one);
- in a CDATA section: the section closed, the reference, the section reopened;
- in a comment or processing instruction: a space (they carry no content).

Every other byte stays xacro's, so a document without such a line is unchanged.
"""

from __future__ import annotations

import re

_BREAK = re.compile(r"(\r\n|\r|\n)(?=\s*::)")  # a line break a `::` line follows
_TOKEN = re.compile(
    r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>"  # comments, CDATA, processing instructions
    r"""|<[^"'<>]*(?:(?:"[^"]*"|'[^']*')[^"'<>]*)*>""",  # tags, quoted values kept whole
    re.DOTALL,
)


def _reference(m: re.Match[str]) -> str:
    return "".join(f"&#{ord(c)};" for c in m.group(1))


def _markup(tok: str) -> str:
    """A comment, CDATA section, processing instruction or tag, rewritten (see the module)."""
    if tok.startswith("<![CDATA["):
        return _BREAK.sub(lambda m: "]]>" + _reference(m) + "<![CDATA[", tok)
    return _BREAK.sub(" ", tok)


def no_workflow_commands(xml: bytes) -> bytes:
    """`xml` (UTF-8) with no line GitHub reads as a workflow command (see the module)."""
    text = xml.decode("utf-8", "surrogateescape")
    if not _BREAK.search(text):
        return xml
    out, at = [], 0
    for m in _TOKEN.finditer(text):
        out.append(_BREAK.sub(_reference, text[at : m.start()]))  # text between markup
        out.append(_markup(m.group(0)))
        at = m.end()
    out.append(_BREAK.sub(_reference, text[at:]))
    return "".join(out).encode("utf-8", "surrogateescape")
