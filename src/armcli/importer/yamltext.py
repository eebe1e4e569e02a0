"""Readable, deterministic YAML text for an imported spec.

Numbers are written as `pi` fractions when one evaluates to exactly the same float
(`pi/2`, `-3*pi/4`), else as the shortest text that reads back as the same float
(Python's repr), so the spec holds the URDF's values exactly. Small mappings and lists
of numbers are written in flow style on one line, as the course spec is; long text
(passthrough XML) as literal blocks.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from armcli.io.oneline import one_line
from armcli.spec.expr import eval_expr

PI_DENOMINATORS = (1, 2, 3, 4, 5, 6, 8, 9, 10, 12, 16, 18, 20, 24, 36, 180)
FLOW_WIDTH = 96  # a flow mapping longer than this is written as a block
_PLAIN = re.compile(r"^[A-Za-z_][A-Za-z0-9_./\-]*$")
_RESERVED = {"true", "false", "yes", "no", "on", "off", "null", "y", "n", "~"}


@dataclass(frozen=True)
class Num:
    """A float to be written exactly (pi fraction or shortest repr)."""

    value: float


@dataclass(frozen=True)
class Block:
    """A long text written as a YAML literal block (`|`)."""

    text: str


class BlockMap(dict[str, Any]):
    """A mapping always written in block style (one key per line), e.g. `control.gains`."""


def pi_fraction(v: float) -> str | None:
    """`k*pi/d` text that evaluates to exactly `v`, for small d; None if there is none."""
    if v == 0.0 or not abs(v) < 100.0:
        return None
    for d in PI_DENOMINATORS:
        k = round(v * d / math.pi)
        if k == 0 or abs(k) > 8 * d or math.gcd(k, d) != 1:
            continue
        sign, a = ("-" if k < 0 else ""), abs(k)
        num = "pi" if a == 1 else f"{a}*pi"
        text = f"{sign}{num}" if d == 1 else f"{sign}{num}/{d}"
        if eval_expr(text) == v:
            return text
    return None


def number(v: float) -> str:
    """The text of a number: integer, exact pi fraction, or shortest round-trip decimal."""
    x = float(v)
    if x == 0.0:
        return "0"
    if x.is_integer() and abs(x) < 1e15:
        return str(int(x))
    return pi_fraction(x) or repr(x)


def scalar(v: Any) -> str:
    """One scalar in YAML: numbers exactly, strings plain when safe, else double-quoted."""
    if isinstance(v, Num):
        return number(v.value)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | float):
        return number(float(v))
    if v is None:
        return "null"
    text = str(v)
    if _PLAIN.match(text) and text.lower() not in _RESERVED:
        return text
    return json.dumps(text, ensure_ascii=False)


def _is_scalar(v: Any) -> bool:
    return not isinstance(v, Mapping | list | tuple | Block)


def _flow(v: Any) -> str | None:
    """`v` in flow style, or None if it has a block or is too nested."""
    if _is_scalar(v):
        return scalar(v)
    if isinstance(v, Block | BlockMap):
        return None
    if isinstance(v, Mapping):
        parts = []
        for k, item in v.items():
            inner = _flow(item)
            if inner is None:
                return None
            parts.append(f"{scalar(k)}: {inner}")
        return "{" + ", ".join(parts) + "}"
    items = [_flow(x) for x in v]
    if any(x is None for x in items):
        return None
    return "[" + ", ".join(str(x) for x in items) + "]"


def _depth(v: Any) -> int:
    if isinstance(v, Mapping):
        return 1 + max((_depth(x) for x in v.values()), default=0)
    if isinstance(v, list | tuple):
        return max((_depth(x) for x in v), default=0)
    return 0


def _value(v: Any, indent: int, width: int) -> list[str]:
    """Lines after `key:` (the first line continues the key's line)."""
    pad = " " * indent
    if isinstance(v, Block):
        body = v.text.rstrip("\n").splitlines()
        return [" |", *(f"{pad}  {ln}".rstrip() if ln.strip() else "" for ln in body)]
    flow = _flow(v)
    if _is_scalar(v) or (flow is not None and _depth(v) <= 3 and len(str(flow)) + indent <= width):
        return [" " + str(flow)]
    if isinstance(v, Mapping):
        return ["", *mapping(v, indent + 2, width)]
    return ["", *sequence(v, indent + 2, width)]


def mapping(data: Mapping[str, Any], indent: int = 0, width: int = FLOW_WIDTH) -> list[str]:
    """The lines of a block mapping at `indent`."""
    pad = " " * indent
    out: list[str] = []
    for key, v in data.items():
        lines = _value(v, indent, width)
        out.append(f"{pad}{scalar(key)}:{lines[0]}")
        out += lines[1:]
    return out


def sequence(items: Sequence[Any], indent: int, width: int = FLOW_WIDTH) -> list[str]:
    """The lines of a block sequence at `indent` (mapping items start on the dash line)."""
    pad = " " * indent
    out: list[str] = []
    for item in items:
        if isinstance(item, Mapping) and item:
            flow = _flow(item)
            if flow is not None and len(flow) + indent + 2 <= width:
                out.append(f"{pad}- {flow}")
                continue
            inner = mapping(item, indent + 2, width)
            out.append(f"{pad}- {inner[0].lstrip()}")
            out += inner[1:]
        elif isinstance(item, Block):
            body = _value(item, indent, width)
            out.append(f"{pad}-{body[0]}")
            out += body[1:]
        else:
            out.append(f"{pad}- {_flow(item)}")
    return out


def document(
    data: Mapping[str, Any],
    header: Sequence[str] = (),
    comments: Mapping[str, Sequence[str]] | None = None,
) -> str:
    """A whole YAML document: `# ` header lines, then the mapping, top-level keys spaced.

    `comments` puts `# ` lines above top-level keys. Comment text passes through
    io.oneline (a file name with a newline would otherwise end the comment and add keys).
    """
    out = [f"# {one_line(h)}".rstrip() for h in header]
    first = True
    for key, v in data.items():
        lines = mapping({key: v})
        if not first and len(lines) > 1:
            out.append("")
        out += [f"# {one_line(c)}".rstrip() for c in (comments or {}).get(key, ())]
        out += lines
        first = False
    return "\n".join(out) + "\n"
