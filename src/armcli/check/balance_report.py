"""The balance and reach part of `check`'s table report: margins, tipping angles, ZMP, reach.

One table per robot with a support polygon: a row per named pose and one for the worst
over the joint range, a column per edge of the polygon (the direction the robot would
tip) with the centre of mass's margin and the slope that tips it that way.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from armcli.analysis.balance import StaticBalance
from armcli.analysis.workspace import ReachPoint, Workspace, describe, verdict
from armcli.io.terminal import Column, FitTable

if TYPE_CHECKING:
    from armcli.sim.tipping import ZmpReport


def balance_items(balance: StaticBalance | None, zmp: ZmpReport | None) -> list[Any]:
    """Rich renderables for the summary (none without a support polygon)."""
    from rich.text import Text

    out: list[Any] = []
    if balance is not None:
        out.append(_table(balance))
    if zmp is not None:
        out.append(Text(zmp.line(), style="red" if zmp.tips else ""))
    return out


def _table(b: StaticBalance) -> Any:
    heads = [f"{d}\n[mm | deg]" for d in b.directions]
    cols = [
        Column("pose", False),
        Column("COM x\n[m]"),
        Column("COM z\n[m]"),
        Column("margin\n[mm]"),
        *(Column(h) for h in heads),
    ]
    table = FitTable(cols, title=_title(b), caption=_caption(b))
    for p in b.poses:
        cells = [_cell(m, a) for m, a in zip(p.margins, p.tip_angles, strict=True)]
        table.add_row(p.name, f"{p.com[0]:.4f}", f"{p.com[2]:.4f}", f"{p.margin * 1e3:.1f}", *cells)
    w = b.worst_overall
    worst = [_cell(p.margins[e], b.worst_tip_angles[e]) for e, p in enumerate(b.worst)]
    table.add_row(
        "worst in range", f"{w.com[0]:.4f}", f"{w.com[2]:.4f}", f"{w.margin * 1e3:.1f}", *worst
    )
    return table


def _cell(margin: float, angle: float) -> str:
    return f"{margin * 1e3:.1f} | {math.degrees(angle):.1f}"


def _title(b: StaticBalance) -> str:
    load = f", {b.payload}" if b.payload else ""
    taken = (
        " (the links you named)"
        if b.contact_tol is None
        else f" (the links within {b.contact_tol * 1e3:.1f} mm of the lowest point at q = 0)"
    )
    return f"static balance on {', '.join(b.contacts)}{taken}{load}"


def _caption(b: StaticBalance) -> str:
    corners = " ".join(f"({x:.3f}, {y:.3f})" for x, y in b.polygon)
    if not b.payload_point:
        holds = "no payload point (no arm)"
    elif b.payload_max is None:
        holds = "no payload keeps the margin everywhere"
    elif math.isinf(b.payload_max):
        holds = f"any payload at {b.payload_point} keeps the margin everywhere"
    else:
        holds = f"up to {b.payload_max:.3g} kg at {b.payload_point} keeps it everywhere"
    return (
        f"support polygon {corners} m, ground at z = {b.ground:.3f} m; per edge: the "
        f"centre of mass's margin and the slope that tips it (rigid wheels, flat ground); "
        f"warning below {b.threshold * 1e3:g} mm: {holds}; robot {b.mass:.4g} kg"
    )


def reach_items(reach: Workspace | None, points: tuple[ReachPoint, ...]) -> list[Any]:
    """One line for the tool point's reach envelope and one per --reach-point."""
    from rich.text import Text

    if reach is None:
        return []
    out: list[Any] = [Text(describe(reach))]
    out += [Text(f"  {verdict(p)}", style="" if p.reachable else "red") for p in points]
    return out
