"""Terminal layout: the width to write for, and tables whose numbers are never cut.

At a terminal, output fits its width (`COLUMNS` when set, as rich reads it); into a
file or a pipe it is written at its natural width, never hard-wrapped, so grep and diff
see whole lines. A `FitTable` keeps every number whole at any width: text columns
(names) wrap first, between words only, so an identifier or a path is never split; when
even that cannot fit, each row becomes a block of `header value` pairs that wraps between
pairs, never inside one.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import IO, Any

from armcli.io.oneline import one_line
from armcli.io.wrap import CONTINUATION, Paragraphs, spans

UNBOUNDED = 1_000_000  # [columns] "no limit": a file or pipe gets each line whole
NAME_MIN = 12  # [columns] a wrapped text column keeps at least this many
GAP = 1  # [columns] between table columns (a space, as in ps or df)


def layout_width(stream: IO[str] | None = None) -> int | None:
    """Columns to lay out for: `COLUMNS`, else the terminal's width, else None (a pipe)."""
    stream = sys.stdout if stream is None else stream
    env = os.environ.get("COLUMNS", "").strip()
    if env.isdigit() and int(env) > 0:
        return int(env)
    isatty = getattr(stream, "isatty", None)
    if isatty is not None and isatty():
        return os.get_terminal_size(stream.fileno()).columns
    return None


def console(stream: IO[str] | None = None, width: int | None = None) -> Any:
    """A rich Console for `stream` (stdout) at `width` or `layout_width(stream)`.

    Without a width (not a terminal, no COLUMNS) lines are not wrapped at all.
    """
    from rich.console import Console

    stream = sys.stdout if stream is None else stream
    width = layout_width(stream) if width is None else width
    return Console(
        file=stream,
        width=UNBOUNDED if width is None else width,
        soft_wrap=width is None,
        highlight=False,
    )


@dataclass(frozen=True)
class Column:
    """One column: a header (lines split on newline) and whether it holds numbers."""

    header: str
    number: bool = True

    def header_lines(self) -> list[str]:
        """The header's lines (units go on the second line, keeping columns narrow)."""
        return self.header.split("\n")


@dataclass
class FitTable:
    """A table whose numbers are never cut or ellipsized; see the module docstring.

    Cells are strings or rich Text. Number columns are right-aligned and never wrap;
    text columns wrap between words down to their longest word (at least NAME_MIN);
    below that, rows are drawn as records. `add_group` starts a group under
    a heading line of its own (a joint's name above its rows), which never widens a column.
    """

    columns: Sequence[Column]
    title: str | None = None
    caption: str | None = None
    items: list[tuple[str, Any]] = field(default_factory=list)  # ("row"|"group"|"rule", data)

    def add_row(self, *cells: Any) -> None:
        """Append a row; one cell per column."""
        if len(cells) != len(self.columns):
            raise ValueError(f"{len(cells)} cells for {len(self.columns)} columns")
        self.items.append(("row", [_text(c) for c in cells]))

    def add_group(self, heading: Any) -> None:
        """Start a group of rows under `heading` (str or rich Text)."""
        self.items.append(("group", _text(heading)))

    def add_section(self) -> None:
        """A rule after the last row."""
        self.items.append(("rule", None))

    def _rows(self) -> list[list[Any]]:
        return [data for kind, data in self.items if kind == "row"]

    def _bounds(self) -> list[tuple[int, int]]:
        """(least, natural) width of each column: numbers whole, text down to NAME_MIN."""
        out = []
        for i, col in enumerate(self.columns):
            head = max(len(line) for line in col.header_lines())
            natural = max([head, *(_len(r[i]) for r in self._rows())])
            word = max([0, *(_longest_word(r[i]) for r in self._rows())])
            least = natural if col.number else min(natural, max(NAME_MIN, head, word))
            out.append((least, natural))
        return out

    def min_width(self) -> int:
        """Narrowest width at which it is still drawn as a table [columns]."""
        return sum(w for w, _ in self._bounds()) + GAP * (len(self.columns) - 1)

    def natural_width(self) -> int:
        """Width without any wrapping [columns]."""
        return sum(w for _, w in self._bounds()) + GAP * (len(self.columns) - 1)

    def widths(self, width: int) -> list[int] | None:
        """Column widths for `width` columns, or None when only records fit."""
        bounds = self._bounds()
        spare = width - self.min_width()
        if spare < 0:
            return None
        out = [least for least, _ in bounds]
        want = [natural - least for least, natural in bounds]
        total = sum(want)
        if total <= spare:
            return [natural for _, natural in bounds]
        given = [w * spare // total for w in want]  # floor shares of the spare columns
        return [o + g for o, g in zip(out, given, strict=True)]

    def __rich_measure__(self, console: Any, options: Any) -> Any:
        from rich.measure import Measurement

        return Measurement(min(self.min_width(), options.max_width), self.natural_width())

    def __rich_console__(self, console: Any, options: Any) -> Iterator[Any]:
        from rich.text import Text

        if self.title:  # wrapped at the console's width, not the table's
            yield Paragraphs(Text(self.title, style="italic"))
        widths = self.widths(options.max_width)
        if widths is None:
            yield from self._records(options.max_width)
        else:
            yield from self._lines(widths)
        if self.caption:
            yield Paragraphs(Text(self.caption, style="dim"))

    def _lines(self, widths: list[int]) -> Iterator[Any]:
        from rich.text import Text

        heads = [c.header_lines() for c in self.columns]
        depth = max(len(h) for h in heads)
        for k in range(depth):  # headers aligned at the bottom, units under names
            cells = [
                _text((h[k - depth + len(h)] if k >= depth - len(h) else ""), "bold") for h in heads
            ]
            yield self._join([[c] for c in cells], widths)
        rule = Text("─" * (sum(widths) + GAP * (len(widths) - 1)), style="dim")
        yield rule
        for kind, data in self.items:
            if kind == "group":
                yield Paragraphs(_text(data, "bold", restyle=True))
            elif kind == "rule":
                yield rule
            else:
                cells = [
                    [cell] if col.number else fold(cell, w)
                    for cell, col, w in zip(data, self.columns, widths, strict=True)
                ]
                yield self._join(cells, widths)

    def _join(self, cells: list[list[Any]], widths: list[int]) -> Any:
        """One table row (several lines when a text cell wrapped), without trailing spaces."""
        from rich.text import Text

        out = Text()
        for k in range(max(len(c) for c in cells)):
            line = Text()
            for i, (lines, col, w) in enumerate(zip(cells, self.columns, widths, strict=True)):
                piece = lines[k].copy() if k < len(lines) else Text()
                pad = " " * (w - len(piece))
                line.append_text(Text(pad).append_text(piece) if col.number else piece.append(pad))
                if i < len(widths) - 1:
                    line.append(" " * GAP)
            line.rstrip()
            out.append_text(line if k == 0 else Text("\n").append_text(line))
        out.no_wrap = True
        return out

    def _records(self, width: int) -> Iterator[Any]:
        """Each row as its text cells (a heading) and wrapped `header value` pairs."""
        for kind, data in self.items:
            if kind == "group":
                yield Paragraphs(_text(data, "bold", restyle=True))
                continue
            if kind == "rule":
                continue
            cols = list(zip(data, self.columns, strict=True))
            names = [c for c, col in cols if not col.number and c.plain]
            pairs = [
                _text(col.header.replace("\n", " ") + " ").append_text(c)
                for c, col in cols
                if col.number
            ]
            if names:
                yield from wrap_parts(names, width, "", "", sep="  ")  # a name is never cut
            yield from wrap_parts(pairs, width, "  ", "  ", sep="   ")


BREAK_AFTER = " "  # a wrapped cell breaks between words: never inside a name or a path


def _longest_word(cell: Any) -> int:
    """The longest space-free run of a cell: an identifier or path a column must hold whole."""
    text = cell.plain if hasattr(cell, "plain") else str(cell)
    return max((len(w) for w in text.split()), default=0)


def fold(cell: Any, width: int) -> list[Any]:
    """`cell` (rich Text) in lines of at most `width`, broken between words if it can."""
    lines = []
    rest = cell.copy()
    while len(rest) > width:
        plain = rest.plain
        # a space at index `width` still ends a line of `width` (the space is dropped)
        cut = max((i + 1 for i in range(width + 1) if plain[i] in BREAK_AFTER), default=width)
        lines.append(rest[:cut].copy())
        rest = rest[cut:]
        lines[-1].rstrip()
    lines.append(rest)
    return lines


def wrap_parts(
    parts: Sequence[Any],
    width: int,
    first: str,
    rest: str,
    sep: str | Sequence[str] = ", ",
) -> list[Any]:
    """Lines of `parts` (rich Text) joined by `sep`, broken only between parts.

    `sep` is one separator or one per gap; a line ends with its separator's non-space
    part. `first` prefixes the first line, `rest` the others. A part wider than a line
    gets a line of its own and is never cut (the line is left longer than `width`).
    """
    from rich.text import Text

    seps = [sep] * max(0, len(parts) - 1) if isinstance(sep, str) else list(sep)
    lines: list[Any] = []
    line = Text(first)
    for i, part in enumerate(parts):
        gap = seps[i - 1] if i else ""
        tail = len(seps[i].rstrip()) if i < len(seps) else 0  # the "," a break would leave
        if i and len(line.plain) + len(gap) + len(part.plain) + tail > width:
            lines.append(line.append(gap.rstrip()))
            line = Text(rest)
            gap = ""
        line.append(gap).append_text(part)
    lines.append(line)
    for out in lines:
        out.no_wrap, out.overflow = True, "ignore"
    return lines


def _len(cell: Any) -> int:
    text = cell.plain if hasattr(cell, "plain") else str(cell)
    return max((len(line) for line in text.split("\n")), default=0)


def _text(cell: Any, style: str = "", restyle: bool = False) -> Any:
    """`cell` as a new rich Text; `restyle` adds `style` to an existing Text too."""
    from rich.text import Text

    if not isinstance(cell, Text):
        return Text(str(cell), style=style)
    out = cell.copy()
    if restyle and style:
        out.stylize(style)
    return out


@dataclass(frozen=True)
class Hanging:
    """`label` then `body` wrapped beside it with a hanging indent; no trailing spaces.

    With an empty label and no indent it is `body` wrapped without trailing spaces.

    The body wraps at word boundaries (a number is one word, so it is never split).
    """

    label: Any  # rich Text
    body: Any  # rich Text, may hold newlines
    indent: int

    def __rich_console__(self, console: Any, options: Any) -> Iterator[Any]:
        from rich.segment import Segment

        width = max(options.max_width - self.indent, NAME_MIN)
        lines = console.render_lines(self.body, options.update_width(width), pad=False)
        label = self.label.copy()
        label.append(" " * (self.indent - len(label) if len(label) < self.indent else bool(label)))
        for i, line in enumerate(lines):
            yield from label.render(console) if i == 0 else [Segment(" " * self.indent)]
            yield from _rstrip(line)
            yield Segment.line()


def _rstrip(line: list[Any]) -> list[Any]:
    """A rendered line without the space a word wrap leaves at its end."""
    from rich.segment import Segment

    if line and line[-1].text.endswith(" ") and not line[-1].control:
        last = line[-1]
        return [*line[:-1], Segment(last.text.rstrip(" "), last.style)]
    return line


def line(out: Any, text: str, style: str | None = None) -> None:
    """Print one line of text on the rich console `out` (`console()`): escaped, fitted."""
    from rich.text import Text

    out.print(Paragraphs(Text(one_line(text), style=style or "")), crop=False)


def fitted(item: Any) -> Any:
    """A renderable as the terminal writer lays it out: text through `Paragraphs`."""
    from rich.text import Text

    return Paragraphs(item) if isinstance(item, str | Text) else item


def fit_line(text: str, stream: IO[str] | None = None) -> str:
    """One plain line for `stream`, wrapped between words at a terminal (or `COLUMNS`).

    Continuation lines are indented CONTINUATION more than the line itself; a word longer
    than the width (a path) is never cut, so it stays whole on a line of its own. Into a
    file or pipe the line is whole, so grep sees every `file:line field: problem` whole.
    """
    width = layout_width(stream)
    if width is None or len(text) <= width:
        return text
    indent = len(text) - len(text.lstrip(" "))
    cont = " " * (indent + CONTINUATION)
    parts = spans(text[indent:], width - indent, width - len(cont))
    lines = [text[indent:][a:b] for a, b in parts]
    return "\n".join([text[:indent] + lines[0], *(cont + line for line in lines[1:])])


def say_line(text: str, stream: IO[str] | None = None) -> None:
    """Write one line (its newlines escaped, as any in a file name) to `stream`, fitted."""
    stream = sys.stdout if stream is None else stream
    stream.write(fit_line(one_line(text), stream) + "\n")


def say(text: str, stream: IO[str] | None = None) -> None:
    """Write `text` (one or more lines) to `stream` (stdout), each escaped and fitted.

    Every line goes through `one_line` (names from files carry no control characters to
    the terminal or a CI log, issue 27), then `fit_line`.
    """
    stream = sys.stdout if stream is None else stream
    for line in text.rstrip("\n").split("\n"):
        stream.write(fit_line(one_line(line), stream) + "\n")
