"""Time parameterisation with TOPP-RA under velocity, acceleration and effort limits.

The geometric path is the planner's polyline itself, each segment traversed with a
quintic smoothstep `h(u) = 10u³ - 15u⁴ + 6u⁵` of the path parameter: the path is C² and
every joint stops at each corner (dq/ds = 0 there), so the timed motion never leaves the
collision-checked segments nor the joint-limit box they lie in. Effort is TOPP-RA's joint
torque constraint with inverse dynamics (Pinocchio RNEA) along the path. TOPP-RA holds the
limits at its grid points; the output is sampled at OUTPUT_RATE_HZ and simulate interpolates
it with quintics, so the limits given to TOPP-RA are scaled by `margin` < 1 and the result
is certified afterwards (plan.certify).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.errors import PlanningError
from armcli.plan.robot import PlanRobot

GRID_PER_SEGMENT = 40  # TOPP-RA grid intervals per polyline segment
OUTPUT_RATE_HZ = 100.0  # [Hz] trajectory points written (the course's controller rate)
UNLIMITED = 1e9  # stands for a limit the URDF does not give (TOPP-RA needs finite numbers)


@dataclass(frozen=True)
class Timed:
    """A time-parameterised motion sampled for output: arrays (P,) and (P, n)."""

    times: np.ndarray  # [s]
    positions: np.ndarray  # [rad or m]
    velocities: np.ndarray  # [rad/s or m/s]
    accelerations: np.ndarray  # [rad/s² or m/s²]

    @property
    def duration(self) -> float:
        """Time of the last point [s]."""
        return float(self.times[-1])


def _h(u: np.ndarray, order: int) -> np.ndarray:
    if order == 0:
        return u**3 * (10.0 - 15.0 * u + 6.0 * u**2)
    if order == 1:
        return 30.0 * u**2 * (1.0 - u) ** 2
    return 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u)


class PolylinePath:
    """The waypoints (W, n) as a C² path over s in [0, W - 1] (TOPP-RA's path interface)."""

    def __init__(self, waypoints: np.ndarray) -> None:
        self.points = np.asarray(waypoints, dtype=float)
        self.deltas = np.diff(self.points, axis=0)

    def __call__(self, s: Any, order: int = 0) -> np.ndarray:
        """Positions (order 0) or derivatives d/ds, d²/ds² at path positions `s`."""
        scalar = np.ndim(s) == 0
        ss = np.atleast_1d(np.asarray(s, dtype=float))
        k = np.clip(np.floor(ss).astype(int), 0, len(self.deltas) - 1)
        u = np.clip(ss - k, 0.0, 1.0)[:, None]
        out = self.deltas[k] * _h(u, order)
        if order == 0:
            out = out + self.points[k]
        result: np.ndarray = out[0] if scalar else out
        return result

    def eval(self, s: Any) -> np.ndarray:
        """Positions at `s`."""
        return self(s, 0)

    def evald(self, s: Any) -> np.ndarray:
        """dq/ds at `s`."""
        return self(s, 1)

    def evaldd(self, s: Any) -> np.ndarray:
        """d²q/ds² at `s`."""
        return self(s, 2)

    @property
    def dof(self) -> int:
        """Number of joints."""
        return int(self.points.shape[1])

    @property
    def path_interval(self) -> np.ndarray:
        """[0, W - 1]."""
        return np.array([0.0, float(len(self.points) - 1)])

    @property
    def waypoints(self) -> None:
        """TOPP-RA asks; gridpoints are given explicitly instead."""
        return None


def inverse_dynamics(robot: PlanRobot) -> Any:
    """tau(x, xd, xdd) of the planned joints [N·m or N]: RNEA, followers moving with leaders."""
    import pinocchio as pin

    model, data = robot.model, robot.model.createData()
    idx = robot.v_indices()
    lead = _follower_map(robot)

    def tau(x: np.ndarray, xd: np.ndarray, xdd: np.ndarray) -> np.ndarray:
        v, a = np.zeros(model.nv), np.zeros(model.nv)
        v[idx], a[idx] = xd, xdd
        for f, leader, mult in lead:
            v[f], a[f] = mult * v[leader], mult * a[leader]
        return np.asarray(pin.rnea(model, data, robot.q(x), v, a))[idx]

    return tau


def _follower_map(robot: PlanRobot) -> list[tuple[int, int, float]]:
    """(follower v index, leader v index, multiplier) for followers of planned joints."""
    model = robot.model
    out = []
    for m in robot.mimic:
        if m.leader in robot.joints and model.existJointName(m.follower):
            f = model.joints[model.getJointId(m.follower)].idx_v
            lead = model.joints[model.getJointId(m.leader)].idx_v
            out.append((int(f), int(lead), float(m.multiplier)))
    return out


def parameterise(robot: PlanRobot, waypoints: np.ndarray, margin: float) -> Timed:
    """Time-optimal motion along the polyline, limits scaled by `margin`; rest at both ends."""
    import toppra
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    logging.getLogger("toppra").setLevel(logging.ERROR)  # library code never prints
    path = PolylinePath(waypoints)
    segments = len(waypoints) - 1
    grid = np.linspace(0.0, float(segments), segments * GRID_PER_SEGMENT + 1)
    cons: list[Any] = [
        constraint.JointVelocityConstraint(np.minimum(robot.velocity, UNLIMITED) * margin),
        constraint.JointAccelerationConstraint(robot.acceleration * margin),
    ]
    if np.any(np.isfinite(robot.effort)):
        effort = np.where(np.isfinite(robot.effort), robot.effort, UNLIMITED)
        lim = np.column_stack([-effort, effort]) * margin
        cons.append(
            constraint.JointTorqueConstraint(
                inverse_dynamics(robot), lim, np.zeros(path.dof), discretization_scheme=1
            )
        )
    solver = algo.TOPPRA(cons, path, gridpoints=grid, parametrizer="ParametrizeConstAccel")
    traj = solver.compute_trajectory(0.0, 0.0)
    if traj is None:
        raise PlanningError("timing", "TOPP-RA found no motion within the limits along the path")
    duration = float(traj.duration)
    n_out = max(2, int(np.ceil(duration * OUTPUT_RATE_HZ)) + 1)
    times = np.linspace(0.0, duration, n_out)
    pos, vel, acc = traj(times, 0), traj(times, 1), traj(times, 2)
    pos[0], pos[-1] = waypoints[0], waypoints[-1]
    vel[0], vel[-1] = 0.0, 0.0
    del toppra
    return Timed(times, np.asarray(pos), np.asarray(vel), np.asarray(acc))
