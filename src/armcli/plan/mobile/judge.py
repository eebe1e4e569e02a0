"""Whether a base pose serves a target: the arm's configuration there, and what forbids it.

At a base pose (x, y, yaw) on the floor the arm takes the configuration that brings the
tool point nearest to the target: in closed form for a planar-reach arm (both elbow
branches, `plan.mobile.planar`), else by the planner's inverse kinematics
(`plan.ik.solve_ik`) in the base frame. The pose serves when that nearest approach is
within the tolerance, the robot there is collision-free (the scene's objects and the floor
against every link, base and arm: `plan.collision`) and statically stable (a positive
tip-over margin at that configuration: `analysis.balance.MarginAt`). Joint limits hold by
construction: both solvers stay inside them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from armcli.analysis.balance import MarginAt
from armcli.plan.ik import solve_ik
from armcli.plan.mobile.virtual import MobileRobot
from armcli.plan.robot import PlanRobot

IK_ATTEMPTS = 4  # restarts of the inverse kinematics at a base pose (general arms)
MARGIN_DIGITS = 9  # configurations equal to this many decimals share a tip-over margin


@dataclass(frozen=True)
class Verdict:
    """One base pose judged: the arm there, how near the tool comes, what forbids it."""

    base: tuple[float, float, float]  # [m, m, rad]
    q: np.ndarray  # the arm's configuration [rad or m]
    error: float  # [m] tool point to target
    margin: float | None  # [m] tip-over margin; None: no support polygon to judge
    blocked: tuple[str, str] | None  # the colliding pair, if any
    why: str  # "" when the pose serves; else "reach", "tip", "park" or "collision"

    @property
    def ok(self) -> bool:
        """Whether the pose serves the target."""
        return not self.why


def world_to_base(bases: np.ndarray, point: np.ndarray) -> np.ndarray:
    """A world point [m] in the frames of bases (N, 3) at (x, y, yaw) on the floor: (N, 3)."""
    c, s = np.cos(bases[:, 2]), np.sin(bases[:, 2])
    dx, dy = point[0] - bases[:, 0], point[1] - bases[:, 1]
    return np.stack([c * dx + s * dy, -s * dx + c * dy, np.full(len(bases), point[2])], axis=1)


class Judge:
    """Judges base poses for one target [m] (world) and tolerance [m]."""

    def __init__(
        self,
        mobile: MobileRobot,
        target: ArrayLike,
        tolerance: float,
        park: Callable[[tuple[float, float, float]], bool] | None = None,
    ) -> None:
        """`park(base)`: a further condition on the pose (the base can drive there)."""
        self.mobile = mobile
        self.park = park
        self.target = np.asarray(target, dtype=float)
        self.tolerance = tolerance
        self._margins: dict[tuple[float, ...], float | None] = {}
        self.checks = 0  # collision checks made (the benchmark reports them)

    @cached_property
    def arm_robot(self) -> PlanRobot:
        """The planning robot with the base held at the origin: the arm's joints planned."""
        return self.mobile.arm_robot()

    def margin(self, q: np.ndarray) -> float | None:
        """The tip-over margin [m] with the arm at q (cached: the base pose does not change it)."""
        stance = self.mobile.stance
        if stance is None:
            return None
        key = tuple(round(float(v), MARGIN_DIGITS) for v in q)
        if key not in self._margins:
            self._margins[key] = self.margin_of(q)
        return self._margins[key]

    @cached_property
    def margin_of(self) -> MarginAt:
        """The balance analysis' margin over the arm's joints."""
        assert self.mobile.stance is not None
        return MarginAt(self.mobile.stance, self.mobile.arm)

    def reach(
        self, bases: np.ndarray, seed: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """The arm at each base pose (N, 3): q (N, B, n) and tool errors (N, B) [m].

        B configurations per pose, each the nearest approach to the target (a planar arm:
        its two elbow branches, inf where a branch does not exist; another arm: the
        inverse kinematics' result, seeded with `seed`).
        """
        bases = np.atleast_2d(np.asarray(bases, dtype=float))
        t_b = world_to_base(bases, self.target)
        planar = self.mobile.planar
        if planar is not None:
            d = t_b - planar.shoulder
            lateral = d @ planar.axis - planar.offset
            q, miss = planar.nearest_batch(d @ planar.e_u, d[:, 2])
            return q, np.sqrt(lateral[:, None] ** 2 + miss**2)
        qs, errors = [], []
        for p in t_b:
            res = solve_ik(self.arm_robot, p, seed_x=seed, attempts=IK_ATTEMPTS)
            x = res.x if res.x is not None else res.closest
            assert x is not None  # every attempt ends somewhere
            qs.append([x])
            errors.append([res.distance])
        return np.array(qs), np.array(errors)

    def judge(self, base: Sequence[float], q: np.ndarray, error: float) -> Verdict:
        """The verdict on the robot at `base` with the arm at q, whose tool misses by `error`."""
        b = (float(base[0]), float(base[1]), float(base[2]))
        if error > self.tolerance:
            return Verdict(b, q, error, None, None, "reach")
        margin = self.margin(q)
        if margin is not None and margin <= 0.0:
            return Verdict(b, q, error, margin, None, "tip")
        if self.park is not None and not self.park(b):
            return Verdict(b, q, error, margin, None, "park")
        self.checks += 1
        pair = self.mobile.checker.first_collision(self.mobile.x(b, q))
        return Verdict(b, q, error, margin, pair, "collision" if pair is not None else "")

    def best(self, base: Sequence[float], q: np.ndarray, errors: np.ndarray) -> Verdict:
        """The first serving configuration of q (B, n) at `base`, else the nearest one's verdict."""
        order = np.argsort(errors, kind="stable")
        first = None
        for k in order:
            if not math.isfinite(float(errors[k])):
                break
            v = self.judge(base, q[k], float(errors[k]))
            if v.ok:
                return v
            first = first or v
        return first or self.judge(base, q[order[0]], float(errors[order[0]]))

    def at(self, base: Sequence[float], seed: np.ndarray | None = None) -> Verdict:
        """The pose's verdict (`best` of its configurations)."""
        q, errors = self.reach(np.asarray([base], dtype=float), seed)
        return self.best(base, q[0], errors[0])
