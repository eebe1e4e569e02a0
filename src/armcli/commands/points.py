"""The `--reach-point x,y,z` option that `check` and `render` share."""

from __future__ import annotations

import math

from armcli.errors import InputError

REACH_POINT_HELP = "x,y,z [m] in the root frame: is it reachable? (repeatable)"


def point_option(text: str, flag: str) -> tuple[float, float, float]:
    """The point "x,y,z" [m] as three finite numbers."""
    try:
        xyz = tuple(float(v) for v in text.split(","))
    except ValueError:
        xyz = ()
    if len(xyz) != 3 or not all(math.isfinite(v) for v in xyz):
        raise InputError(f"expected x,y,z in metres, got {text!r}", field=flag)
    return (xyz[0], xyz[1], xyz[2])
