"""Inverse kinematics of the tool point: damped least squares on Pinocchio, random restarts.

The tool point (robot.tool: the spec's `arm.tool`, else the deepest link) reaches `xyz`
[m] in the robot's root frame, and, when `rotation` is given, the tool link's orientation
matches it. Each attempt iterates dx = Jᵀ (J Jᵀ + λ² I)⁻¹ e from a start (the first
attempt: `seed_x`; then uniform random joint values from a seeded generator), clipped into
the joint limits; a converged solution in collision is rejected and the next attempt
starts. The closest distance reached is reported when no attempt succeeds.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from armcli.plan.robot import PlanRobot

POSITION_TOL = 1e-4  # [m] a solution's tool point is this close to the target
ROTATION_TOL = 1e-3  # [rad] and its orientation this close (angle of the difference)
DAMPING = 1e-3  # λ: keeps the step bounded near singular configurations
MAX_ITERATIONS = 60  # per attempt
ATTEMPTS = 40  # the seeded start, then random restarts
MAX_STEP = 0.5  # [rad or m] largest joint change per iteration


@dataclass(frozen=True)
class IkResult:
    """Joint values reaching the target (None if none was found) and the closest distance."""

    x: np.ndarray | None
    distance: float  # [m] tool point to target at the best attempt
    angle: float  # [rad] orientation error there (0 for a position goal)
    attempts: int
    closest: np.ndarray | None = None  # the best attempt's values (a miss within a caller's
    # looser tolerance still serves it: base placement)


def tool_pose(robot: PlanRobot, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tool point [m] and tool link rotation in the root frame at planned joint values `x`."""
    q = robot.q(x)
    return robot.robot.tool_position(q), robot.robot.frame_pose(robot.tool_frame, q)[:3, :3]


class _Solver:
    def __init__(self, robot: PlanRobot, xyz: np.ndarray, rotation: np.ndarray | None) -> None:
        import pinocchio as pin

        self.pin, self.robot = pin, robot
        self.data = robot.robot.data
        self.xyz, self.rotation = xyz, rotation
        self.cols = _columns(robot)

    def error(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Task error and Jacobian (world-aligned, at the tool point) w.r.t. planned joints."""
        robot = self.robot
        p, r, J6 = robot.robot.frame_jacobian(robot.q(x))  # the tool point, its lever arm
        Jv = J6[:3] + np.cross(J6[3:].T, r).T  # v_point = v_frame + ω × r
        e = self.xyz - p
        if self.rotation is None:
            return e, self.cols(Jv)
        R = self.data.oMf[robot.tool_frame].rotation  # placed by the Jacobian's kinematics
        e_rot = self.pin.log3(self.rotation @ R.T)
        return np.concatenate([e, e_rot]), self.cols(np.vstack([Jv, J6[3:]]))

    def run(self, x0: np.ndarray) -> tuple[np.ndarray, float, float]:
        lo, hi = self.robot.lower, self.robot.upper
        x = np.clip(x0, lo, hi)
        for _ in range(MAX_ITERATIONS):
            e, J = self.error(x)
            dist, ang = float(np.linalg.norm(e[:3])), float(np.linalg.norm(e[3:]))
            if dist < POSITION_TOL and ang < ROTATION_TOL:
                return x, dist, ang
            JJt = J @ J.T + DAMPING**2 * np.eye(J.shape[0])
            dx = J.T @ np.linalg.solve(JJt, e)
            big = float(np.max(np.abs(dx)))
            if big > MAX_STEP:
                dx *= MAX_STEP / big
            x = np.clip(x + dx, lo, hi)
        e, _ = self.error(x)
        return x, float(np.linalg.norm(e[:3])), float(np.linalg.norm(e[3:]))


def _columns(robot: PlanRobot) -> Callable[[np.ndarray], np.ndarray]:
    """Model Jacobian (rows, nv) -> planned-joint Jacobian, followers added to their leaders."""
    model = robot.model
    idx = robot.v_indices()
    extra = []
    for m in robot.mimic:
        if m.leader in robot.joints and model.existJointName(m.follower):
            f = int(model.joints[model.getJointId(m.follower)].idx_v)
            extra.append((f, robot.joints.index(m.leader), float(m.multiplier)))

    def cols(J: np.ndarray) -> np.ndarray:
        out = J[:, idx].copy()
        for f, k, mult in extra:
            out[:, k] += mult * J[:, f]
        return out

    return cols


def solve_ik(
    robot: PlanRobot,
    xyz: np.ndarray,
    rotation: np.ndarray | None = None,
    *,
    seed_x: np.ndarray | None = None,
    seed: int = 0,
    free: Callable[[np.ndarray], bool] | None = None,
    attempts: int = ATTEMPTS,
) -> IkResult:
    """Joint values putting the tool point at `xyz` (and the tool at `rotation`), or the best miss.

    `free(x)`: whether a solution is collision-free (rejected solutions count as misses).
    """
    solver = _Solver(robot, np.asarray(xyz, dtype=float), rotation)
    rng = np.random.default_rng(seed)
    best = (np.inf, np.inf)
    closest = None
    start = seed_x if seed_x is not None else 0.5 * (robot.lower + robot.upper)
    for k in range(attempts):
        x0 = start if k == 0 else rng.uniform(robot.lower, robot.upper)
        x, dist, ang = solver.run(x0)
        if dist < POSITION_TOL and ang < ROTATION_TOL and (free is None or free(x)):
            return IkResult(x, dist, ang, k + 1)
        if (dist, ang) < best:
            best, closest = (dist, ang), x
    return IkResult(None, best[0], best[1], attempts, closest)
