"""Certify a trajectory before it is written, independently of how it was planned.

The points are read back as `simulate` reads them (trajectory.message) and interpolated as
it interpolates them (trajectory.reference: quintic segments); the reference is sampled at
CERTIFY_RATE_HZ and every sample is checked against the joint position, velocity,
acceleration and effort limits (effort: inverse dynamics, RNEA, of the sampled motion) and
for collisions with every enabled pair (robot, scene, ground). The first violation is
returned; `plan` refuses to write a trajectory that has one.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.plan.collision import CollisionChecker
from armcli.plan.robot import PlanRobot
from armcli.plan.timing import Timed, inverse_dynamics
from armcli.trajectory.message import Trajectory
from armcli.trajectory.reference import build_reference

CERTIFY_RATE_HZ = 1000.0  # [Hz] samples checked, whatever the output rate
RELATIVE_TOL = 1e-9  # velocity, acceleration and effort may reach their limit, not pass it
# [rad or m] how far the interpolation between two points may pass a position limit the
# motion starts or ends at: the quintic through TOPP-RA's samples can dip ~1e-7 rad below a
# limit the joint leaves from (the points themselves are always inside: LIMIT_TOL).
POSITION_SLACK = 1e-6


@dataclass(frozen=True)
class Violation:
    """The first limit or collision broken: what, which joint or pair, when, by how much."""

    kind: str  # position | velocity | acceleration | effort | collision
    time: float  # [s]
    where: str  # joint name, or "link and link"
    value: float = 0.0
    limit: float = 0.0

    def text(self) -> str:
        """One line for an error message."""
        if self.kind == "collision":
            return f"collision between {self.where} at t = {self.time:.3f} s"
        return (
            f"{self.kind} of {self.where} is {self.value:.6g}, beyond its limit "
            f"{self.limit:.6g}, at t = {self.time:.3f} s"
        )


@dataclass(frozen=True)
class Samples:
    """The interpolated motion at the certification rate: (T,) and (T, n)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray


def sample(robot: PlanRobot, timed: Timed, rate: float = CERTIFY_RATE_HZ) -> Samples:
    """Positions, velocities and accelerations of simulate's interpolation at `rate`."""
    traj = Trajectory(
        joint_names=robot.joints,
        times=timed.times,
        positions=timed.positions,
        velocities=timed.velocities,
        accelerations=timed.accelerations,
    )
    ref = build_reference(traj, robot.joints, timed.positions[0])
    steps = int(np.floor(timed.duration * rate))
    t = np.append(np.arange(steps + 1) / rate, timed.duration)
    q, v = ref.sample(t)
    idx = np.clip(np.searchsorted(ref.knots, t, side="right") - 1, 0, len(ref.coeffs) - 1)
    tau = (t - ref.knots[idx])[:, None]
    c = ref.coeffs[idx]
    a = 2.0 * c[:, 2] + tau * (6.0 * c[:, 3] + tau * (12.0 * c[:, 4] + tau * 20.0 * c[:, 5]))
    a[t >= ref.knots[-1]] = timed.accelerations[-1]
    return Samples(t, q, v, a)


def _limit(
    s: Samples, values: np.ndarray, limit: np.ndarray, kind: str, joints: tuple[str, ...]
) -> Violation | None:
    excess = np.abs(values) - limit * (1.0 + RELATIVE_TOL)
    if not np.any(excess > 0):
        return None
    k, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
    return Violation(kind, float(s.t[k]), joints[j], float(values[k, j]), float(limit[j]))


def kinematic_violation(robot: PlanRobot, s: Samples, compiled: Any = None) -> Violation | None:
    """The worst position, velocity, acceleration or effort excess, or None.

    `compiled`: the compiled planner's scene (plan.native), which computes the torques.
    """
    names = robot.joints
    below = robot.lower - POSITION_SLACK - s.q
    above = s.q - robot.upper - POSITION_SLACK
    for excess in (below, above):
        if np.any(excess > 0):
            k, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
            bound = robot.lower[j] if excess is below else robot.upper[j]
            return Violation("position", float(s.t[k]), names[j], float(s.q[k, j]), float(bound))
    for values, limit, kind in (
        (s.v, robot.velocity, "velocity"),
        (s.a, robot.acceleration, "acceleration"),
    ):
        found = _limit(s, values, limit, kind, names)
        if found is not None:
            return found
    if np.any(np.isfinite(robot.effort)):
        return _limit(s, _torques(robot, s, compiled), robot.effort, "effort", names)
    return None


def _torques(robot: PlanRobot, s: Samples, compiled: Any) -> np.ndarray:
    """Joint torques (T, n) of the sampled motion: RNEA, compiled where it can be."""
    if compiled is not None:
        arrays = (np.ascontiguousarray(a, dtype=float) for a in (s.q, s.v, s.a))
        tau: np.ndarray = compiled.inverse_dynamics(*arrays, robot.v_indices())
        return tau
    tau_of = inverse_dynamics(robot)
    return np.array([tau_of(q, v, a) for q, v, a in zip(s.q, s.v, s.a, strict=True)])


def collision_violation(checker: CollisionChecker, s: Samples) -> Violation | None:
    """The first sample in collision, or None.

    Every enabled pair at the first sample; after it, the pairs a planned joint moves (the
    others keep their relative pose along the whole motion). The compiled sweep
    (plan/_native/certify.cpp) gives the same verdict at every sample and proves most of
    them free with distance bounds instead of collision queries.
    """
    if checker.native is not None:
        k, index, _queries, _bounds = checker.native.sweep(np.ascontiguousarray(s.q, dtype=float))
        if k < 0:
            return None
        a, b = checker.pair_names(index)
        return Violation("collision", float(s.t[k]), f"{a} and {b}")
    for k, (t, q) in enumerate(zip(s.t, s.q, strict=True)):
        pair = checker.first_collision(q, every_pair=k == 0)
        if pair is not None:
            return Violation("collision", float(t), f"{pair[0]} and {pair[1]}")
    return None


def certify(robot: PlanRobot, checker: CollisionChecker, timed: Timed) -> Violation | None:
    """The first violation of the trajectory as simulate will run it, or None."""
    s = sample(robot, timed)
    return kinematic_violation(robot, s, checker.native) or collision_violation(checker, s)
