"""Time parameterisation with TOPP-RA under velocity, acceleration and effort limits.

The geometric path is the planner's polyline itself, and each straight segment is timed on
its own, from rest to rest: the timed motion never leaves the collision-checked segments
nor the joint-limit box they lie in. On a straight segment dq/ds is constant and d²q/ds² is
zero, so TOPP-RA's piecewise-constant path acceleration keeps joint velocity and
acceleration within their limits between its grid points too, not only at them. Effort is
TOPP-RA's joint torque constraint with inverse dynamics (Pinocchio RNEA) along the path.
The whole motion is sampled at OUTPUT_RATE_HZ and the points get the velocities and
accelerations of the C² cubic spline through them (simulate's quintic interpolation then
follows that spline exactly). The spline averages TOPP-RA's bang-bang accelerations over a
sample interval and overshoots their jumps by up to ~27 % (the decay ratio 2 - √3 of
cubic spline interpolation), so the limits given to TOPP-RA are scaled by `margin` < 1 and
the result is certified afterwards (plan.certify).

With the compiled planner, `blend` > 0 rounds the path's corners first (plan/_native/
timing.cpp): each corner becomes a quadratic Bézier of radius `blend` times the shorter
neighbouring segment, kept only where the planner's own state check finds it free every
`step` (else halved, at last a stop), so the motion passes its corners without stopping and
stays inside the joint-limit box. TOPP-RA then times each stretch between stops in one pass.
The Python path (no extension) stops at every corner.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.errors import PlanningError
from armcli.plan.duration import check_duration
from armcli.plan.robot import PlanRobot

GRID_PER_SEGMENT = 30  # TOPP-RA grid intervals per polyline segment
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


class SegmentPath:
    """A straight segment q(s) = a + s (b - a), s in [0, 1] (TOPP-RA's path interface)."""

    def __init__(self, a: np.ndarray, b: np.ndarray) -> None:
        self.a = np.asarray(a, dtype=float)
        self.d = np.asarray(b, dtype=float) - self.a

    def __call__(self, s: Any, order: int = 0) -> np.ndarray:
        """Positions (order 0) or derivatives d/ds, d²/ds² at path positions `s`."""
        ss = np.asarray(s, dtype=float)
        shape = (*ss.shape, len(self.a))
        if order == 0:
            return np.asarray(self.a + ss[..., None] * self.d)
        return np.broadcast_to(self.d if order == 1 else 0.0 * self.d, shape).copy()

    def eval(self, s: Any) -> np.ndarray:
        """Positions at `s`."""
        return self(s, 0)

    def evald(self, s: Any) -> np.ndarray:
        """dq/ds at `s`."""
        return self(s, 1)

    def evaldd(self, s: Any) -> np.ndarray:
        """d²q/ds² at `s` (zero)."""
        return self(s, 2)

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.a)

    @property
    def path_interval(self) -> np.ndarray:
        """[0, 1]."""
        return np.array([0.0, 1.0])

    @property
    def waypoints(self) -> None:
        """TOPP-RA asks; gridpoints are given explicitly instead."""
        return None


def inverse_dynamics(robot: PlanRobot) -> Any:
    """tau(x, xd, xdd) of the planned joints [N·m or N]: RNEA, followers moving with leaders."""
    nv = robot.model.nv
    idx = robot.v_indices()
    lead = _follower_map(robot)

    def tau(x: np.ndarray, xd: np.ndarray, xdd: np.ndarray) -> np.ndarray:
        v, a = np.zeros(nv), np.zeros(nv)
        v[idx], a[idx] = xd, xdd
        for f, leader, mult in lead:
            v[f], a[f] = mult * v[leader], mult * a[leader]
        return robot.robot.inverse_dynamics(robot.q(x), v, a)[idx]

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


def _spline(times: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Velocities and accelerations at the points of the C² cubic spline through them.

    simulate's quintic between two points with these end values is that cubic exactly,
    so what is certified is one smooth function (at rest at both ends).
    """
    from scipy.interpolate import CubicSpline

    zero = np.zeros(pos.shape[1])
    spline = CubicSpline(times, pos, bc_type=((1, zero), (1, zero)))
    return np.asarray(spline(times, 1)), np.asarray(spline(times, 2))


def _compiled(robot: PlanRobot, waypoints: np.ndarray, margin: float, compiled: Any,
              blend: float, step: float) -> Timed:  # fmt: skip
    """`parameterise` in the compiled planner (plan/_native/timing.cpp)."""
    effort = np.zeros(0)
    if np.any(np.isfinite(robot.effort)):
        effort = np.where(np.isfinite(robot.effort), robot.effort, UNLIMITED) * (0.5 + 0.5 * margin)
    out = compiled.time_polyline(
        np.ascontiguousarray(waypoints, dtype=float),
        np.minimum(robot.velocity, UNLIMITED) * margin,
        np.asarray(robot.acceleration, dtype=float) * margin,
        effort,
        robot.v_indices(),
        GRID_PER_SEGMENT,
        OUTPUT_RATE_HZ,
        blend=blend,
        step=step,
    )
    if isinstance(out, int):
        raise PlanningError(
            "timing",
            f"TOPP-RA found no motion within the limits along segment {out + 1} of the path",
        )
    return Timed(*out)


def _constraints(robot: PlanRobot, margin: float) -> list[Any]:
    import toppra.constraint as constraint

    cons: list[Any] = [
        constraint.JointVelocityConstraint(np.minimum(robot.velocity, UNLIMITED) * margin),
        constraint.JointAccelerationConstraint(robot.acceleration * margin),
    ]
    if np.any(np.isfinite(robot.effort)):
        effort = np.where(np.isfinite(robot.effort), robot.effort, UNLIMITED)
        # effort is mostly gravity, which the spline does not change: half the margin
        lim = np.column_stack([-effort, effort]) * (0.5 + 0.5 * margin)
        tau = inverse_dynamics(robot)
        cons.append(
            constraint.JointTorqueConstraint(
                tau, lim, np.zeros(len(effort)), discretization_scheme=1
            )
        )
    return cons


def parameterise(
    robot: PlanRobot, waypoints: np.ndarray, margin: float, compiled: Any = None,
    *, blend: float = 0.0, step: float = 0.02,
) -> Timed:  # fmt: skip
    """Time-optimal motion along the polyline, limits scaled by `margin`; rest at each waypoint.

    `compiled`: the compiled planner's scene (plan.native), whose TOPP-RA is the toppra C++
    library's; without it, TOPP-RA's Python package (the same algorithm and LP solver).
    `blend` (compiled only): round the corners, checked every `step` (see the module).
    """
    if compiled is not None:
        return _compiled(robot, waypoints, margin, compiled, blend, step)
    import toppra.algorithm as algo

    logging.getLogger("toppra").setLevel(logging.ERROR)  # library code never prints
    cons = _constraints(robot, margin)
    grid = np.linspace(0.0, 1.0, GRID_PER_SEGMENT + 1)
    pieces, starts = [], [0.0]
    for k in range(len(waypoints) - 1):
        path = SegmentPath(waypoints[k], waypoints[k + 1])
        solver = algo.TOPPRA(cons, path, gridpoints=grid, parametrizer="ParametrizeConstAccel")
        traj = solver.compute_trajectory(0.0, 0.0)
        if traj is None:
            raise PlanningError(
                "timing",
                f"TOPP-RA found no motion within the limits along segment {k + 1} of the path",
            )
        pieces.append(traj)
        starts.append(starts[-1] + float(traj.duration))
    duration = starts[-1]
    check_duration(duration)  # before sampling it at OUTPUT_RATE_HZ (issue 42)
    n_out = max(2, int(np.ceil(duration * OUTPUT_RATE_HZ)) + 1)
    times = np.linspace(0.0, duration, n_out)
    seg = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(pieces) - 1)
    pos = np.empty((n_out, waypoints.shape[1]))
    for k, traj in enumerate(pieces):
        sel = seg == k
        if np.any(sel):
            local = np.clip(times[sel] - starts[k], 0.0, float(traj.duration))
            pos[sel] = np.asarray(traj(local, 0))
    pos[0], pos[-1] = waypoints[0], waypoints[-1]
    return Timed(times, pos, *_spline(times, pos))
