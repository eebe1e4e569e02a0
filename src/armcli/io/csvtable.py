"""A numeric CSV table read under bounds checked before anything is allocated.

`view --replay` reads a recorded run. The csv module builds a whole row before
returning it, so a 198 MB file of two rows of 99 million cells peaked at 2.6 GB
before any limit applied. Here the file size is checked before opening, the
header line is read with a length cap and bounds the number of columns, every
data line is read with a length cap derived from the column count (so no row can
be bigger than the header allows), and the row and cell counts are checked as
rows arrive; values go straight into float64 blocks. Duplicate column names are
refused (the second one silently replaced the first).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

import numpy as np

from armcli.errors import InputError
from armcli.io.userfile import open_regular

MAX_NAME_CHARS = 256  # a column name
MAX_CELL_CHARS = 64  # a number written as text (repr of a float is at most 24)
_BLOCK_ROWS = 4096


@dataclass(frozen=True)
class CsvBounds:
    """What a table may hold: checked while reading, never after allocating."""

    max_bytes: int
    max_columns: int
    max_rows: int
    max_cells: int


@dataclass(frozen=True)
class NumericTable:
    """Column names (line 1) and the values, one row per data line (blank lines skipped)."""

    header: tuple[str, ...]
    values: np.ndarray  # [rows, columns] float64
    lines: np.ndarray  # [rows] the file line of each row, for messages


def _line(fh: TextIO, limit: int, source: str, number: int, what: str) -> str:
    """One line of at most `limit` characters (its newline excluded)."""
    text = fh.readline(limit + 2)
    if len(text.rstrip("\r\n")) > limit:
        raise InputError(f"{what} longer than {limit} characters", file=source, line=number)
    return text


def _cells(text: str, source: str, number: int) -> list[str]:
    try:
        return next(csv.reader([text]), [])
    except csv.Error as exc:
        raise InputError(f"unreadable CSV: {exc}", file=source, line=number) from None


def _header(fh: TextIO, source: str, max_columns: int) -> tuple[str, ...]:
    limit = max_columns * (MAX_NAME_CHARS + 1)
    names = _cells(_line(fh, limit, source, 1, "header line"), source, 1)
    if len(names) > max_columns:
        raise InputError(f"{len(names)} columns, at most {max_columns}", file=source, line=1)
    header = tuple(n.strip() for n in names)
    seen: set[str] = set()
    for name in header:
        if name in seen:
            raise InputError(f"column {name!r} appears twice", file=source, line=1)
        seen.add(name)
    return header


def _value(text: str, column: str, line: int, source: str, blank_ok: bool) -> float:
    if blank_ok and text.strip().lower() in ("", "nan"):
        return math.nan
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(
            f"expected a finite number, got {text!r}", file=source, line=line, field=column
        )
    return value


def _rows(
    fh: TextIO, source: str, header: tuple[str, ...], bounds: CsvBounds
) -> Iterator[tuple[int, list[str]]]:
    """(line number, cells) of each non-blank data line, every bound checked first."""
    width = len(header)
    limit = width * (MAX_CELL_CHARS + 1)
    max_rows = min(bounds.max_rows, bounds.max_cells // max(width, 1))
    number, rows = 1, 0
    while True:
        number += 1
        text = _line(fh, limit, source, number, f"line of {width} cells")
        if not text:
            return
        if not text.strip():
            continue
        rows += 1
        if rows > max_rows:
            raise InputError(
                f"more than {max_rows:,} data rows ({bounds.max_cells:,} cells at most)",
                file=source,
                line=number,
            )
        cells = _cells(text, source, number)
        if len(cells) != width:
            raise InputError(f"{len(cells)} cells, header has {width}", file=source, line=number)
        yield number, cells


def read_numeric_csv(
    path: str | Path, bounds: CsvBounds, blank_ok: Callable[[str], bool], what: str = "CSV"
) -> NumericTable:
    """The numbers of a CSV with a header line; `blank_ok(column)`: empty/nan cells are NaN.

    InputError (file, line, column) for anything out of bounds or not a finite number.
    """
    source = str(path)
    with open_regular(path, max_bytes=bounds.max_bytes, what=what) as raw:
        fh = io.TextIOWrapper(raw, encoding="utf-8", newline="")
        try:
            header = _header(fh, source, bounds.max_columns)
            blanks = [blank_ok(h) for h in header]
            blocks: list[np.ndarray] = []
            lines: list[int] = []
            block = np.empty((_BLOCK_ROWS, len(header)))
            k = 0
            for number, cells in _rows(fh, source, header, bounds):
                if k == _BLOCK_ROWS:
                    blocks.append(block)
                    block, k = np.empty((_BLOCK_ROWS, len(header))), 0
                for i, cell in enumerate(cells):
                    block[k, i] = _value(cell, header[i], number, source, blanks[i])
                lines.append(number)
                k += 1
        except UnicodeDecodeError:
            raise InputError(f"{what} is not UTF-8 text", file=source) from None
        finally:
            fh.detach()
    blocks.append(block[:k])
    return NumericTable(header, np.concatenate(blocks), np.asarray(lines, dtype=np.int64))
