"""Where a line breaks: the one rule armcli's terminal writer (io.terminal) applies.

A line breaks at spaces only, so a word (a number, a name, a path) is never cut; a word
longer than the line stays where it is rather than leaving a label such as `error:` alone
on a line; no line starts with `::` (GitHub Actions would read a workflow command);
continuation lines are indented CONTINUATION more than the line they continue.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

MIN_WIDTH = 12  # [columns] a paragraph is never laid out narrower than this
CONTINUATION = 2  # [columns] a wrapped line's continuation: its own indent plus this
# a word that never starts a line: `=` or a unit armcli prints after a number
GLUED = re.compile(r"(=|m|mm|cm|s|ms|rad|deg|°|kg|N|N·m|Hz|px|%)[,;:.)]*$")


@dataclass(frozen=True)
class Paragraphs:
    """Lines of rich `text` as `fit_line` lays out plain ones: the rich writer's rule.

    Each line (split on newlines) wraps between words; its continuation lines are
    indented CONTINUATION more than the line's own indent, so an indented line's wrap
    stays under it; a word longer than the width (a path) is never cut; no line ends
    in a space.
    """

    text: Any  # rich Text or str, may hold newlines

    def __rich_console__(self, console: Any, options: Any) -> Iterator[Any]:
        from rich.segment import Segment
        from rich.text import Text

        text = self.text if isinstance(self.text, Text) else Text(str(self.text))
        for line in text.split("\n", allow_blank=True):
            indent = len(line.plain) - len(line.plain.lstrip(" "))
            width = max(options.max_width - indent - CONTINUATION, MIN_WIDTH)
            for i, part in enumerate(_words(line[indent:], width)):
                yield Segment(" " * (indent + (CONTINUATION if i else 0)))
                yield from part.render(console)
                yield Segment.line()


def _words(text: Any, width: int) -> list[Any]:
    """`text` (rich Text) in lines broken at spaces only (`spans`), each without its spaces."""
    return [text[a:b] for a, b in spans(text.plain, width, width)]


def spans(plain: str, first: int, rest: int) -> list[tuple[int, int]]:
    """(start, end) of each line of `plain` broken at spaces: `first` columns, then `rest`.

    A word never breaks: one longer than a line stays where it is (moving it to a line
    of its own would not make it fit, and would leave a label such as `error:` alone),
    and a word starting `::` never starts a line (a GitHub Actions workflow command). A
    unit or `=` never starts a line either: it goes down with the word before it
    (`(0.450, 0.000, 0.020) m`, `z = 0.000`), so nobody reads a number without its unit.
    """
    words = [(m.start(), m.end()) for m in re.finditer(r"[^ ]+", plain)]
    if not words:
        return [(0, 0)]
    lines = [[words[0]]]
    for a, b in words[1:]:
        line, room = lines[-1], first if len(lines) == 1 else rest
        if (b - line[0][0]) <= room or (b - a) > rest or plain.startswith("::", a):
            line.append((a, b))  # it fits; or it fits nowhere; or it must not start a line
        elif (
            len(line) > 1
            and GLUED.match(plain, a, b)
            and b - line[-1][0] <= rest
            and not plain.startswith("::", line[-1][0])
        ):
            lines.append([line.pop(), (a, b)])  # the unit and its number, together
        else:
            lines.append([(a, b)])
    return [(line[0][0], line[-1][1]) for line in lines]
