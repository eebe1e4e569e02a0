"""Joint values as a user types them, one rule for every command, and the limits' edge.

`0.3,pi/4` (in the given joints' order) or `elbow=pi/4,shoulder=0.3`, each value a number
or an expression of `pi` as the spec writes angles (spec.expr: `pi/2`, `-3*pi/4`):
`plan --from/--to`, `render --q`.

A value beyond a limit by at most SNAP is that limit, with a note: limits are printed at
display precision (`[0, 1.5708]` for pi/2), and a user who types back what they read
(1.5708 > pi/2 by 3.7e-6) means the stop, not an error.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from armcli.errors import InputError
from armcli.spec.expr import eval_expr

SNAP = 1e-4  # [rad or m] see the module docstring


def parse_joint_values(text: str, joints: Sequence[str], field: str) -> dict[str, float]:
    """`text` -> {joint: value}; InputError naming `field` (with the valid joints) if not so.

    The positional form needs one value per joint; the named form may name a subset.
    """
    items = [s.strip() for s in text.split(",") if s.strip()]
    order = ", ".join(joints) or "(none)"
    named = bool(items) and all("=" in s for s in items)
    if not named and len(items) != len(joints):
        raise InputError(
            f"expected {len(joints)} value(s), one for each of {order}, or "
            f"joint=value pairs; got {text!r}",
            field=field,
        )
    pairs = [s.split("=", 1) for s in items] if named else list(zip(joints, items, strict=True))
    out: dict[str, float] = {}
    for name, value in pairs:
        name = name.strip()
        if name not in joints:
            raise InputError(f"unknown joint {name!r}; valid: {order}", field=field)
        try:
            out[name] = eval_expr(value)
        except (ValueError, ArithmeticError) as exc:
            raise InputError(f"{name}: {exc}", field=field) from None
    return out


def snap_to_limits(
    values: Mapping[str, float], limits: Mapping[str, tuple[float, float]]
) -> tuple[dict[str, float], list[str]]:
    """Values within SNAP beyond a limit set onto it, and a note for each one moved."""
    out, notes = dict(values), []
    for name, value in values.items():
        lo, hi = limits.get(name, (float("-inf"), float("inf")))
        for bound, side, beyond in ((lo, "lower", lo - value), (hi, "upper", value - hi)):
            if 0.0 < beyond <= SNAP:
                out[name] = bound
                notes.append(
                    f"{name} = {value:g} is taken as its {side} limit {bound:.9g} "
                    f"({beyond:.2g} beyond it, within {SNAP:g})"
                )
    return out, notes
