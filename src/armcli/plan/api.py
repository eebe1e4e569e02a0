"""The planning API: `planning_context` once per robot and scene, then `plan_motion`, `solve_goal`.

    ctx = planning_context(robot, scene, disabled)        # collision model, built once
    x_goal = solve_goal(ctx, xyz=(0.3, 0, 0.5), start=x_start)   # IK (optional)
    result = plan_motion(ctx, x_start, x_goal, PlanOptions(seed=1))
    result.document                                       # certified JointTrajectory YAML

`plan_motion` plans a path (geometric), times it (timing), writes it (output), reads the
written document back as `simulate` does and certifies it (certify); a trajectory with a
kinematic violation is re-timed with tighter limits (MARGINS), and a PlanningError is
raised when none passes. Nothing here prints or writes files.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from armcli.defaults import MAX_COORDINATE_M
from armcli.errors import InputError, PlanningError
from armcli.io.scene import Scene
from armcli.plan.certify import certify
from armcli.plan.collision import PADDING, CollisionChecker
from armcli.plan.duration import check_motion_time
from armcli.plan.geometric import plan_path
from armcli.plan.ik import IkResult, solve_ik
from armcli.plan.output import read_back, trajectory_yaml
from armcli.plan.robot import PlanRobot
from armcli.plan.timing import Timed, parameterise
from armcli.robot.frames import rpy_rotation

# TOPP-RA limit scales tried until the certification passes: the output spline overshoots
# an acceleration jump by up to ~27 % (plan.timing); a stop at a corner of the path is a
# jump of twice the limit, so paths with corners start lower.
MARGINS = (0.78, 0.6, 0.45)
MARGINS_CORNERS = (0.6, 0.45, 0.3)
# Corner blends (plan.timing; compiled planner only): radius as a fraction of the shorter
# segment at the corner. A blended motion that fails its certification at every margin is
# timed again stopping at each corner (BLENDS' 0.0).
BLEND = 0.45
BLENDS = (BLEND, 0.0)
LIMIT_SLACK = 1e-9  # [rad or m] a start or goal may sit this far beyond a limit (rounding)


@dataclass(frozen=True)
class PlanOptions:
    """How to plan: OMPL planner name, timeout [s], seed, collision-check step [rad or m]."""

    planner: str = "rrtconnect"
    timeout: float = 1.0
    seed: int = 0
    step: float = 0.02
    comment: str = ""  # first lines of the written document


@dataclass(frozen=True)
class PlanResult:
    """A certified motion: the path, its timing, the document to write and the figures."""

    joints: tuple[str, ...]
    path: np.ndarray  # (W, n) waypoints after shortcutting
    timed: Timed  # as read back from `document`
    document: bytes  # JointTrajectory YAML
    planning_time_s: float  # planning + shortcutting + parameterisation
    path_time_s: float  # planning + shortcutting (the geometric path alone)
    certify_time_s: float  # [s] wall clock: reading back and certifying
    margin: float  # the limit scale TOPP-RA used
    notes: tuple[str, ...] = ()  # what the request's reading decided (plan.request)
    certify_cpu_s: float = 0.0  # [s] the same, CPU time of this process (load-independent)
    path_cpu_s: float = 0.0  # [s] path_time_s in CPU time of this process (every thread)

    @property
    def duration_s(self) -> float:
        """Duration of the motion [s]."""
        return self.timed.duration

    @property
    def path_length_rad(self) -> float:
        """Joint-space length of the path (Euclidean, [rad] for revolute joints)."""
        return float(np.sum(np.linalg.norm(np.diff(self.path, axis=0), axis=1)))


@dataclass(frozen=True)
class PlanningContext:
    """A robot with its obstacles and collision pairs, ready to plan many motions."""

    robot: PlanRobot
    checker: CollisionChecker


def planning_context(
    robot: PlanRobot, scene: Scene | None = None, disabled: Iterable[tuple[str, str]] = ()
) -> PlanningContext:
    """Build the collision model once; `disabled`: link pairs never checked (the SRDF's)."""
    return PlanningContext(robot, CollisionChecker(robot, scene or Scene(), disabled))


def _check_limits(robot: PlanRobot, x: np.ndarray, what: str) -> None:
    for name, v, lo, hi in zip(robot.joints, x, robot.lower, robot.upper, strict=True):
        if not (lo - LIMIT_SLACK <= v <= hi + LIMIT_SLACK):
            raise PlanningError(
                f"{what}-limits",
                f"{what} is outside the joint limits: {name} = {v:g}, limits [{lo:g}, {hi:g}]",
            )


def _check_free(ctx: PlanningContext, x: np.ndarray, what: str) -> None:
    pair = ctx.checker.first_collision(x, every_pair=True)
    if pair is not None:
        raise PlanningError(
            f"{what}-collision", f"{what} is in collision: {pair[0]} and {pair[1]}", pair=pair
        )


def values(ctx: PlanningContext, x: Sequence[float] | np.ndarray, what: str) -> np.ndarray:
    """Validated joint values: one finite number per planned joint."""
    arr = np.asarray(list(x), dtype=float)
    n = len(ctx.robot.joints)
    if arr.shape != (n,):
        raise InputError(f"give {n} value(s), one per joint of {', '.join(ctx.robot.joints)}; "
                         f"got {arr.size}", field=what)  # fmt: skip
    if not np.all(np.isfinite(arr)):
        raise InputError("values must be finite numbers", field=what)
    return arr


def plan_motion(
    ctx: PlanningContext,
    start: Sequence[float] | np.ndarray,
    goal: Sequence[float] | np.ndarray,
    options: PlanOptions,
) -> PlanResult:
    """A certified, time-parameterised collision-free motion from `start` to `goal`.

    Raises PlanningError (start/goal out of limits or in collision, no path within the
    timeout, no trajectory passing the certification) and InputError for bad values.
    """
    robot = ctx.robot
    xs, xg = values(ctx, start, "start"), values(ctx, goal, "goal")
    _check_limits(robot, xs, "start")
    _check_limits(robot, xg, "goal")
    xs, xg = np.clip(xs, robot.lower, robot.upper), np.clip(xg, robot.lower, robot.upper)
    _check_free(ctx, xs, "start")
    _check_free(ctx, xg, "goal")
    limits = {n: (float(lo), float(hi)) for n, lo, hi in zip(robot.joints, robot.lower,
                                                            robot.upper, strict=True)}  # fmt: skip
    frame = str(robot.model.frames[1].name) if robot.model.nframes > 1 else ""
    check_motion_time(robot, np.array([xs, xg]))  # no path is faster than the straight one
    ctx.checker.pad(PADDING, (xs, xg))
    _import_planners(ctx, options.planner)  # their import (~1.5 s) is not planning time
    t0, c0 = time.perf_counter(), time.process_time()
    path = plan_path(ctx.checker, robot.lower, robot.upper, xs, xg, planner=options.planner,
                     timeout=options.timeout, seed=options.seed, step=options.step)  # fmt: skip
    t_path, c_path = time.perf_counter() - t0, time.process_time() - c0
    check_motion_time(robot, path)
    return _timed(ctx, path, options, frame, limits, t0, (t_path, c_path))


def _timed(
    ctx: PlanningContext, path: np.ndarray, options: PlanOptions, frame: str,
    limits: dict[str, tuple[float, float]], t0: float, t_path: tuple[float, float],
) -> PlanResult:  # fmt: skip
    """Time the path, write it, read it back and certify it: the first timing that passes.

    Blended corners first (with the compiled planner), then stops at every corner; each
    with ever smaller limit margins while the violation is kinematic. `t_path`: the path's
    (wall, CPU) time [s].
    """
    robot, native = ctx.robot, ctx.checker.native
    corners = len(path) > 2
    t_plan, t_cert, c_cert, last = 0.0, 0.0, 0.0, None
    for blend in BLENDS if corners and native is not None else (0.0,):
        for margin in MARGINS_CORNERS if corners else MARGINS:
            timed = parameterise(robot, path, margin, native, blend=blend, step=options.step)
            t_plan = time.perf_counter() - t0
            doc = trajectory_yaml(robot.joints, timed, frame_id=frame, comment=options.comment)
            t1, c1 = time.perf_counter(), time.process_time()
            back = read_back(doc, limits)
            last = certify(robot, ctx.checker, back)
            t_cert += time.perf_counter() - t1
            c_cert += time.process_time() - c1
            if last is None:
                return PlanResult(robot.joints, path, back, doc, t_plan, t_path[0], t_cert,
                                  margin, certify_cpu_s=c_cert, path_cpu_s=t_path[1])  # fmt: skip
            if last.kind == "collision":
                break
    assert last is not None
    raise PlanningError("certify", f"the planned trajectory fails its certification: {last.text()}")


def _import_planners(ctx: PlanningContext, planner: str) -> None:
    """Import the Python planners the path will use (none with the compiled planner)."""
    if ctx.checker.native is None or planner != "rrtconnect":
        import ompl.geometric

        del ompl
    if ctx.checker.native is None:
        import toppra.algorithm

        del toppra


def solve_goal(
    ctx: PlanningContext,
    xyz: Sequence[float],
    rpy: Sequence[float] | None = None,
    *,
    start: Sequence[float] | np.ndarray | None = None,
    seed: int = 0,
) -> np.ndarray:
    """Joint values putting the tool point at `xyz` [m] (root frame), collision-free.

    `rpy` [rad]: also the tool link's orientation (fixed-axis roll, pitch, yaw). Without it,
    an arm of 6 or more joints keeps the start's tool orientation and a smaller arm solves
    for the position only. PlanningError("ik") says the closest distance reached.
    """
    robot = ctx.robot
    target = np.asarray(list(xyz), dtype=float)
    if target.shape != (3,) or not np.all(np.abs(target) <= MAX_COORDINATE_M):  # NaN too
        raise InputError(f"give x,y,z: three numbers within ±{MAX_COORDINATE_M:g} m",
                         field="to-xyz")  # fmt: skip
    x0 = values(ctx, start, "start") if start is not None else None
    rotation = None
    if rpy is not None:
        r = np.asarray(list(rpy), dtype=float)
        if r.shape != (3,) or not np.all(np.isfinite(r)):
            raise InputError("give r,p,y: three finite numbers [rad]", field="to-rpy")
        rotation = rpy_rotation(r)
    elif len(robot.joints) >= 6 and x0 is not None:
        from armcli.plan.ik import tool_pose

        rotation = tool_pose(robot, x0)[1]
    res: IkResult = solve_ik(robot, target, rotation, seed_x=x0, seed=seed,
                             free=lambda x: ctx.checker.first_collision(x, every_pair=True)
                             is None)  # fmt: skip
    if res.x is None:
        what = f"{res.distance:.4g} m" + (
            f", {math.degrees(res.angle):.3g}°" if rotation is not None else ""
        )
        raise PlanningError(
            "ik", f"no collision-free IK solution for the tool point; closest: {what} away"
        )
    return res.x
