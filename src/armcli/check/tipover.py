"""Rules `com-outside-support` and `support-margin`: will the robot tip over standing still?

The robot's support polygon (its wheels' and caster's ground contacts, `analysis.ground`)
and its centre of mass with the payload (`analysis.balance`), at every named pose and at
the worst configuration of the joint range. A robot whose base is bolted down (an arm
alone: no wheel touches the ground) is skipped with a note, unless contact links are
named. Each finding names the pose and the payload that still holds there.
"""

from __future__ import annotations

import math
from dataclasses import replace

from armcli.analysis import balance
from armcli.analysis.balance import PoseBalance, StaticBalance
from armcli.analysis.ground import mesh_loader
from armcli.analysis.stance import NoStance, Payload, Stance, stance_of
from armcli.check.context import Context, poses
from armcli.check.findings import Collector, Value
from armcli.robot.file import floating_of
from armcli.robot.tool import tool_point

NEAR_NAMED = 1e-3  # [m] a range's worst within this of a named pose's is that pose's finding


def check(c: Context) -> None:
    """Build the stance, analyse it, report findings; the result goes to the summary."""
    stance = stance_for(c)
    if stance is None:
        return
    stance = c.stance = _without_wheel_payload(c, stance)
    named = [(name, v) for name, v in poses(c) if name not in ("lower", "upper")]
    c.balance = balance.analyse(stance, named, c.opts.tipover.min_margin)
    _report(c.balance, c.out, c.urdf.line)


def stance_for(c: Context) -> Stance | None:
    """The robot on its ground contacts with the payload, or None (and a note) when it has none."""
    opts, spec, file = c.opts.tipover, c.opts.spec, c.opts.robot_file
    candidates = None
    if spec is not None and opts.contact_links is None:
        base = spec.mounted_base()
        candidates = set(base.links) if base is not None else set()
    missing: list[str] = []
    point = tool_point(c.urdf, spec)
    if opts.payload_link is not None:
        link, xyz = opts.payload_link, (0.0, 0.0, 0.0)
    elif point is not None:
        link, xyz = point.link, point.xyz
    else:
        return None
    found = stance_of(
        c.urdf,
        candidates=candidates,
        declared=opts.contact_links,
        mesh=mesh_loader(c.urdf, c.opts.mesh_search(), missing),
        payload=Payload(opts.payload, link, xyz),
        floating=None if file is None else floating_of(file, c.urdf),
    )
    if missing:
        c.notes.append(f"ground contacts: meshes not found, left out: {', '.join(missing)}")
    if isinstance(found, NoStance):
        c.notes.append(f"static balance skipped: {found.reason}")
        return None
    return found


def _without_wheel_payload(c: Context, stance: Stance) -> Stance:
    """A base without an arm: its deepest link is a wheel, no place for a payload."""
    p = stance.payload
    if p is None or c.opts.tipover.payload_link is not None or p.link not in stance.ground.links:
        return stance
    if p.mass > 0:
        c.notes.append(
            f"payload left out: the tool point {p.link} touches the ground (no arm); "
            "name its link with --payload-link"
        )
    return replace(stance, payload=None)


def _report(b: StaticBalance, out: Collector, line: int | None) -> None:
    reported = []
    for p in b.poses:
        if p.margin < b.threshold:
            _add(b, p, f"pose {p.name!r}", out, line, p.payload_max)
            reported.append(p.margin)
    w = b.worst_overall
    if w.margin < b.threshold and all(w.margin < r - NEAR_NAMED for r in reported):
        q = ", ".join(f"{n}={v:.4g}" for n, v in w.q)
        _add(b, w, f"over the joint range (at {q})", out, line, b.payload_max)


def round_down(x: float, digits: int = 2) -> float:
    """X rounded down to `digits` significant digits (a payload that still holds)."""
    if x <= 0 or not math.isfinite(x):
        return max(0.0, x)
    step = 10.0 ** (math.floor(math.log10(x)) - digits + 1)
    return float(f"{math.floor(x / step + 1e-9) * step:.{digits}g}")


NO_ARM_HINT = (
    "move the base's heavy parts (battery, boards) toward the polygon's centre, or widen the "
    "support (wheel track, caster position)"
)


def _add(
    b: StaticBalance,
    p: PoseBalance,
    where: str,
    out: Collector,
    line: int | None,
    holds: float | None,
) -> None:
    e = p.edge
    direction = b.directions[e]
    load = f" with {b.payload}" if b.payload else ""
    if p.margin < 0:
        rule = "com-outside-support"
        what = f"centre of mass {-p.margin * 1e3:.1f} mm outside the support polygon"
    else:
        rule = "support-margin"
        what = (
            f"centre of mass only {p.margin * 1e3:.1f} mm inside the support polygon "
            f"(threshold {b.threshold * 1e3:g} mm)"
        )
    text = f"{where}: {what}, toward {direction}{load}; "
    fix: dict[str, Value] = {}
    if not b.payload_point:  # no payload point: a base without an arm
        text = text[:-2]
    elif holds is None:
        text += "it does not hold even unloaded there"
    elif math.isinf(holds):
        text += f"any payload at {b.payload_point} holds there"
    else:
        text += f"up to {holds:.3g} kg at {b.payload_point} holds there"
        fix["payload"] = round_down(holds)
    out.add(
        rule,
        line,
        text,
        fix,
        pose=p.name,
        margin=p.margin,
        direction=direction,
        tip_angle_deg=math.degrees(p.tip_angles[e]),
        com=list(p.com),
        q=[v for _, v in p.q],
        payload=b.payload,
    )
    if not b.payload_point:  # the rule's hint speaks of an arm this robot does not have
        out.findings[-1] = replace(out.findings[-1], hint=NO_ARM_HINT)
