"""Option values that are lists and tuples: parsed, and refused, where click parses them.

`typer.Option(..., parser=numbers("--kp"))` turns `--kp 20,30` into `(20.0, 30.0)`
before the command runs, so a malformed value is armcli's one-line error naming the
flag (exit 2), and the command receives typed values. Each parser is one rule, shared
by every command that takes such a value.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NewType

from armcli.defaults import MAX_COORDINATE_M
from armcli.errors import InputError

Names = NewType("Names", tuple)  # type: ignore[type-arg]  # tuple[str, ...]; typer needs a class
Numbers = NewType("Numbers", tuple)  # type: ignore[type-arg]  # tuple[float, ...]

REACH_POINT_HELP = "x,y,z [m] in the root frame: is it reachable? (repeatable)"
SIZE_LIMITS = (100, 8000)  # [px] each side of a rendered image


def names(text: str) -> Names:
    """`a, b,c` -> ("a", "b", "c"); blanks dropped (an empty value names nothing)."""
    return Names(tuple(n.strip() for n in text.split(",") if n.strip()))


def numbers(flag: str, count: int | None = None, what: str = "") -> Callable[[str], Numbers]:
    """A parser of comma-separated finite numbers (exactly `count` when given).

    `what` names the expected form in the error (`x,y,z in metres`).
    """
    form = what or (f"{count} comma-separated numbers" if count else "comma-separated numbers")

    def parse(text: str) -> Numbers:
        try:
            values = tuple(float(v) for v in text.split(",") if v.strip())
        except ValueError:
            raise InputError(f"expected {form}, got {text!r}", field=flag) from None
        if not values or (count is not None and len(values) != count):
            raise InputError(f"expected {form}, got {text!r}", field=flag)
        if not all(math.isfinite(v) for v in values):
            raise InputError(f"expected finite numbers, got {text!r}", field=flag)
        return Numbers(values)

    return parse


def point(flag: str) -> Callable[[str], Numbers]:
    """A parser of the point `x,y,z` [m], each within ±MAX_COORDINATE_M (1e308 overflowed)."""
    parse_numbers = numbers(flag, 3, "x,y,z in metres")

    def parse(text: str) -> Numbers:
        values = parse_numbers(text)
        if not all(abs(v) <= MAX_COORDINATE_M for v in values):
            raise InputError(
                f"each coordinate must be within ±{MAX_COORDINATE_M:g} m, got {text!r}", field=flag
            )
        return values

    return parse


def size(text: str) -> Numbers:
    """`--size WIDTHxHEIGHT` in pixels, each side within SIZE_LIMITS."""
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise InputError(f"{text!r}: expected WIDTHxHEIGHT in pixels", field="--size") from None
    lo, hi = SIZE_LIMITS
    if not (lo <= w <= hi and lo <= h <= hi):
        raise InputError(f"{text!r}: each side must be {lo}..{hi} px", field="--size")
    return Numbers((w, h))
