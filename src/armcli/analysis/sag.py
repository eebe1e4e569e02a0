"""Where an arm held by position control settles against gravity: the sag of a PD(+I) hold.

A joint held by `tau = Kp (q_ref - q) + I` (ros2_control's JointTrajectoryController on an
effort interface, Gazebo's PID plugins, armcli simulate's PD loop) comes to rest where the
motors balance gravity: `Kp (q_ref - q) + I = g(q)`. Without an integral term (I = 0) it
settles `g / Kp` away from where it was commanded: MoveIt then refuses the next plan
("start point deviates from current robot state more than allowed_start_tolerance"). An
integral term supplies up to its clamp `i_max` of the torque, so only `g` beyond the
clamp is left to the proportional term. The joints not held stay where they are put
(locked), joint stops hold a joint that would leave its range; friction and damping do not
move a steady state and are left out (friction only widens a band around it).

Solved by Newton's method on the held joints with Pinocchio's gravity derivatives,
clipped to the joint range; tests/analysis/test_sag.py holds it against armcli simulate
running the same gains from the commanded pose.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from armcli.robot.model import Robot

Array = NDArray[np.float64]
NEWTON_STEPS = 60
RESIDUAL_TOL = 1e-10  # [N·m] |Kp e + I - g| at which the hold counts as settled
PASS_ROUNDS = 8  # rounds of the search for the Kp that holds within a tolerance
PASS_MARGIN = 1.05  # the suggested Kp keeps the sag 5 % inside the tolerance


@dataclass(frozen=True)
class Hold:
    """The gains holding `joints`: Kp [N·m/rad or N/m] and the integral's torque cap i_max.

    `i_max` is 0 without an integral term (or with a clamp of 0), inf when unclamped.
    """

    joints: tuple[str, ...]
    kp: tuple[float, ...]
    i_max: tuple[float, ...]

    @staticmethod
    def pd(joints: Sequence[str], kp: Sequence[float]) -> Hold:
        """A proportional hold without integral action."""
        return Hold(tuple(joints), tuple(float(k) for k in kp), tuple(0.0 for _ in joints))


@dataclass(frozen=True)
class Sag:
    """A held pose's steady state: where each held joint settles and how far from q_ref."""

    q_ref: Mapping[str, float]  # [rad or m] the commanded pose (held joints)
    q: Mapping[str, float]  # where they settle
    torque: Mapping[str, float]  # [N·m or N] gravity torque at the settled pose
    converged: bool  # False: no steady state found (gains too weak for the arm)

    def deviation(self, joint: str) -> float:
        """|q - q_ref| of one held joint [rad or m]."""
        return abs(self.q[joint] - self.q_ref[joint])

    @property
    def worst(self) -> tuple[str, float]:
        """The held joint farthest from its command, and that distance."""
        joint = max(self.q, key=self.deviation)
        return joint, self.deviation(joint)


def settle(robot: Robot, q_ref: Mapping[str, float], hold: Hold) -> Sag:
    """The steady state of `hold` at `q_ref` (joints absent from it at rest, `Robot.rest`)."""
    joints = [robot.joint(n) for n in hold.joints]
    vidx = np.array([j.idx_v for j in joints], dtype=int)
    lower = np.array([j.lower for j in joints])
    upper = np.array([j.upper for j in joints])
    kp, i_max = np.array(hold.kp, dtype=float), np.array(hold.i_max, dtype=float)
    ref = np.array([float(q_ref.get(n, robot.rest(n))) for n in hold.joints])
    base = robot.q(robot.follow(dict(q_ref)))
    x, converged = ref.copy(), False
    for _ in range(NEWTON_STEPS):
        g, dg = _gravity(robot, base, hold.joints, x, vidx)
        left = g - np.clip(g, -i_max, i_max)  # what the integral term cannot carry
        r = kp * (ref - x) - left
        stopped = ((x <= lower) & (r < 0)) | ((x >= upper) & (r > 0))  # a stop carries it
        if np.all(np.abs(np.where(stopped, 0.0, r)) < RESIDUAL_TOL):
            converged = True
            break
        carried = np.abs(g) <= i_max  # the integral term takes these joints' gravity
        J = -np.diag(kp) - np.where(carried[:, None], 0.0, dg)
        free = ~stopped
        step = np.zeros_like(x)
        try:
            step[free] = np.linalg.solve(J[np.ix_(free, free)], -r[free])
        except np.linalg.LinAlgError:
            break
        x = np.clip(x + step, lower, upper)
    g, _ = _gravity(robot, base, hold.joints, x, vidx)
    names = hold.joints
    return Sag(
        dict(zip(names, ref.tolist(), strict=True)),
        dict(zip(names, x.tolist(), strict=True)),
        dict(zip(names, g.tolist(), strict=True)),
        converged and bool(np.all(np.isfinite(x))),
    )


def _gravity(
    robot: Robot, base: Array, joints: Sequence[str], x: Array, vidx: NDArray[np.int_]
) -> tuple[Array, Array]:
    """G and dg/dq of the held joints at `x` (the other joints as in `base`)."""
    q = robot.q(robot.follow(dict(zip(joints, x.tolist(), strict=True))), base=base)
    g, dg = robot.gravity(q), robot.gravity_jacobian(q)
    return g[vidx], dg[np.ix_(vidx, vidx)]


def passing_kp(robot: Robot, q_ref: Mapping[str, float], hold: Hold, tol: float) -> float:
    """The least uniform Kp [N·m/rad] keeping every held joint within `tol` of `q_ref`.

    Two significant digits, rounded up; inf when none does.
    """
    k = max(hold.kp) if hold.kp else 0.0
    sag = settle(robot, q_ref, hold)
    for _ in range(PASS_ROUNDS):
        joint, dev = sag.worst
        if sag.converged and dev <= tol:
            return _round_up(k)
        need = abs(sag.torque[joint]) / tol * PASS_MARGIN
        k = max(k * PASS_MARGIN, need)
        sag = settle(robot, q_ref, Hold(hold.joints, tuple(k for _ in hold.joints), hold.i_max))
    return _round_up(k) if sag.converged and sag.worst[1] <= tol else math.inf


def _round_up(x: float) -> float:
    """`x` rounded up to two significant digits (a gain a user writes)."""
    if x <= 0 or not math.isfinite(x):
        return x
    scale = 10.0 ** (math.floor(math.log10(x)) - 1)
    return math.ceil(x / scale - 1e-9) * scale
