"""Joint rules: limit order and sign, axis, radians, and agreement with the spec."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from armcli.check.findings import Collector
from armcli.check.structure import finite
from armcli.spec.joint_types import LIMITED_TYPES, ONE_DOF_TYPES
from armcli.urdf.doc import Joint, Urdf

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

AXIS_UNIT_TOL = 1e-6
# A revolute limit that is a whole multiple of 5 from 15 to 720 (45, 90, 180, 360...)
# is almost surely degrees typed as radians; larger values are "unlimited" sentinels,
# non-round ones (3*pi) and round ones up to 10 rad (bolt's and solo's -10..10, 1.6
# turns) are deliberate multi-turn ranges.
DEGREES_MIN = 15.0
DEGREES_MAX = 720.0
DEGREES_STEP = 5.0
SPEC_LIMIT_TOL = 1e-9


def check(
    urdf: Urdf, spec: RobotSpec | None, out: Collector, notes: list[str] | None = None
) -> None:
    """Joint rules: axis and limits of each moving joint, then the arm limits against the spec."""
    driven = driven_joints(urdf)
    passive: list[str] = []
    for j in urdf.joints:
        if j.type in ONE_DOF_TYPES:
            _axis(j, out)
        if j.limit is not None and j.type in LIMITED_TYPES:
            _limits(j, out, passive if driven is not None and j.name not in driven else None)
    if passive and notes is not None:
        notes.append(
            f"passive joint(s) {', '.join(passive)}: effort or velocity limit 0, and no "
            "<transmission> or <ros2_control> drives them (springs, free wheels): not checked"
        )
    if spec is not None:
        _spec_limits(urdf, spec, out)


def _axis(j: Joint, out: Collector) -> None:
    if j.axis is None or not finite(*j.axis):
        return
    norm = math.sqrt(sum(a * a for a in j.axis))
    if norm == 0.0:
        out.add("axis", j.axis_line, f"joint {j.name!r}: axis is zero", joint=j.name)
    elif abs(norm - 1.0) > AXIS_UNIT_TOL:
        out.add(
            "axis-unit",
            j.axis_line,
            f"joint {j.name!r}: axis {list(j.axis)} has length {norm:.6g}",
            joint=j.name,
            norm=norm,
        )


def driven_joints(urdf: Urdf) -> set[str] | None:
    """The joints a `<transmission>` or `<ros2_control>` block drives; None when there is none.

    With none, nothing tells a passive joint from an actuated one, so every joint is held
    to actuator limits. With some, a joint they leave out is passive (LoCoBot's spring
    wheel-drop joints: effort and velocity 0 mean "no motor", not a typo).
    """
    names = {j for t in urdf.transmissions for j in t.joints}
    names |= {j for b in urdf.ros2_control for j in b.commands}
    return names or None


def _limits(j: Joint, out: Collector, passive: list[str] | None = None) -> None:
    """Order, degrees and actuator limits; `passive` collects a passive joint's zero limits."""
    lim = j.limit
    assert lim is not None
    lo, hi = lim.lower, lim.upper
    if finite(lo, hi) and not lim.missing_bounds:  # missing ones are `missing-limit`
        assert lo is not None and hi is not None
        if lo >= hi:
            out.add(
                "limit-order",
                lim.line,
                f"joint {j.name!r}: lower {lo:g} is not below upper {hi:g}",
                joint=j.name,
                lower=lo,
                upper=hi,
            )
        if j.type == "revolute" and any(_looks_like_degrees(x) for x in (lo, hi)):
            out.add(
                "limit-degrees",
                lim.line,
                f"joint {j.name!r}: limits [{lo:g}, {hi:g}] rad "
                f"= [{math.degrees(lo):.0f}, {math.degrees(hi):.0f}] deg",
                joint=j.name,
                lower=lo,
                upper=hi,
            )
    for attr in ("effort", "velocity"):
        v = getattr(lim, attr)
        if passive is not None and v == 0:
            if j.name not in passive:
                passive.append(j.name)
        elif v is not None and finite(v) and v <= 0:
            out.add(
                "limit-effort-velocity",
                lim.line,
                f"joint {j.name!r}: {attr} limit {v:g} must be > 0",
                joint=j.name,
                **{attr: v},
            )


def _looks_like_degrees(x: float) -> bool:
    a = abs(x)
    return (
        DEGREES_MIN <= a <= DEGREES_MAX and abs(a / DEGREES_STEP - round(a / DEGREES_STEP)) < 1e-9
    )


def _spec_limits(urdf: Urdf, spec: RobotSpec, out: Collector) -> None:
    """The arm joints' limits must equal the spec's (e.g. the course's 0..pi/2)."""
    by_name = {j.name: j for j in urdf.joints}
    for name, sj in spec.arm.joints.items():
        if sj.limit is None or name not in by_name:
            continue
        uj = by_name[name]
        ul = uj.limit
        given = {
            "lower": sj.limit.lower,
            "upper": sj.limit.upper,
            "effort": sj.limit.effort,
            "velocity": sj.limit.velocity,
        }
        want = {k: v for k, v in given.items() if v is not None}  # a continuous joint: no bounds
        got = {k: (getattr(ul, k) if ul is not None else None) for k in want}
        bad = [k for k in want if (g := got[k]) is None or abs(g - want[k]) > SPEC_LIMIT_TOL]
        if bad:
            detail = ", ".join(f"{k} {_g(got[k])} (spec {want[k]:g})" for k in bad)
            out.add(
                "spec-limits",
                ul.line if ul else uj.line,
                f"joint {name!r}: {detail}",
                joint=name,
                **{f"spec_{k}": want[k] for k in bad},
            )


def _g(v: float | None) -> str:
    return "missing" if v is None else f"{v:g}"
