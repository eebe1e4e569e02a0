"""A robot's 1-DoF joints: where each sits in q and v, its URDF limits, where it rests.

The rest rule, once for every consumer (`rest`): a joint nobody sets sits at 0 when its
range allows it, else in the middle of its range. It is MoveIt's default state
(`RobotState::setToDefaultValues`), so the collision matrix's `Default` pairs, a plan's
joints that are not planned, the exported MuJoCo `home` keyframe, the mock hardware's
start and the rendered pose agree with what MoveIt shows; and the middle keeps a joint
off its stops, where a start at the nearest limit would rest on one.
`Robot.q` and `JointMap` are the one place a continuous joint (revolute without limits)
is written as the pair (cos, sin) of its angle (nq = 2, nv = 1).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray


def span(lower: float, upper: float) -> tuple[float, float]:
    """A joint range to sample over [rad or m]: [lower, upper], else [-pi, pi].

    [-pi, pi] when the range is not finite and in order (a continuous joint's is infinite).
    """
    if not (math.isfinite(lower) and math.isfinite(upper)) or lower > upper:
        return -math.pi, math.pi
    return lower, upper


def rest(lower: float, upper: float) -> float:
    """Where a joint nobody sets sits [rad or m]: 0 if [lower, upper] holds it, else the middle.

    The range is `span`'s: a continuous joint (or one without a usable range) rests at 0.
    """
    lo, hi = span(lower, upper)
    return 0.0 if lo <= 0.0 <= hi else 0.5 * (lo + hi)


@dataclass(frozen=True)
class Joint:
    """One 1-DoF joint of the model: where it sits in q and v, and its URDF numbers."""

    name: str
    idx_q: int
    idx_v: int
    continuous: bool  # stored as (cos, sin) in q
    lower: float  # [rad or m]; -inf for a continuous joint (no stop)
    upper: float  # [rad or m]; inf for a continuous joint
    effort: float  # [N·m or N]; inf when the URDF gives none (<= 0 or not finite)
    velocity: float  # [rad/s or m/s] as the URDF gives it (<= 0 or inf: none)
    damping: float  # [N·m·s/rad or N·s/m]
    friction: float  # [N·m or N]

    @property
    def span(self) -> tuple[float, float]:
        """The finite range to sample it over [rad or m] (`span` of its limits)."""
        return span(self.lower, self.upper)

    @property
    def rest(self) -> float:
        """Where it sits when nobody sets it [rad or m] (`rest`, the module's rule)."""
        return rest(self.lower, self.upper)


def put(q: NDArray[np.float64], joint: Joint, x: float) -> None:
    """Set one joint in q: the angle of a continuous joint as its (cos, sin) pair."""
    if joint.continuous:
        q[joint.idx_q], q[joint.idx_q + 1] = math.cos(x), math.sin(x)
    else:
        q[joint.idx_q] = x


def joint_table(model: Any) -> tuple[Joint, ...]:
    """The model's 1-DoF joints in tree order; multi-DoF joints (floating, planar) are left out."""
    out = []
    for jid in range(1, model.njoints):
        jm = model.joints[jid]
        if jm.nv != 1:
            continue
        continuous = jm.nq == 2
        lo = -math.inf if continuous else float(model.lowerPositionLimit[jm.idx_q])
        hi = math.inf if continuous else float(model.upperPositionLimit[jm.idx_q])
        effort = float(model.effortLimit[jm.idx_v])
        out.append(
            Joint(
                name=str(model.names[jid]),
                idx_q=int(jm.idx_q),
                idx_v=int(jm.idx_v),
                continuous=continuous,
                lower=lo,
                upper=hi,
                effort=effort if effort > 0 and math.isfinite(effort) else math.inf,
                velocity=float(model.velocityLimit[jm.idx_v]),
                damping=float(model.damping[jm.idx_v]),
                friction=float(model.friction[jm.idx_v]),
            )
        )
    return tuple(out)


@dataclass(frozen=True)
class JointMap:
    """Where chosen joints and their mimic followers sit in q (`Robot.joint_map`)."""

    template: NDArray[np.float64]  # q with the chosen joints at 0, the others at rest
    lin: tuple[NDArray[np.int64], NDArray[np.int64]]  # (q, x) indices of 1-nq chosen joints
    cont: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]  # (cos, sin, x)
    followers: tuple[tuple[int, bool, str, str, float, float], ...]  # as `Robot.joint_map`
    joints: tuple[str, ...]
    rest: Mapping[str, float]

    def q(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The configuration with the chosen joints at `x` [rad or m]."""
        q = self.template.copy()  # index arrays kept apart: the planner calls this per state
        q[self.lin[0]] = x[self.lin[1]]
        if len(self.cont[2]):
            q[self.cont[0]] = np.cos(x[self.cont[2]])
            q[self.cont[1]] = np.sin(x[self.cont[2]])
        if self.followers:
            values = dict(zip(self.joints, x.tolist(), strict=True))
            for iq, continuous, name, leader, mult, offset in self.followers:  # leaders first
                v = mult * values.get(leader, self.rest.get(leader, 0.0)) + offset
                values[name] = v
                if continuous:  # as `put`, inlined: per state
                    q[iq], q[iq + 1] = math.cos(v), math.sin(v)
                else:
                    q[iq] = v
        return q
