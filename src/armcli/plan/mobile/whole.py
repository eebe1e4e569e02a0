"""One plan for a robot on a differential drive: where to park, how to drive there, the arm.

`plan_whole` (what `armcli plan --base` calls): the arm stays in its travel configuration
(the start pose, `home` by default) while the base drives; placement (`plan.mobile.place`)
chooses the pose of least driving that serves the target and that the base can reach with
the arm stowed, the base path is planned on the floor plan (`plan.mobile.basepath`),
timed within the wheels' limits (`plan.mobile.basetime`) and certified by the 3-D checker
turn by turn and leg by leg; then the arm's motion from the travel configuration to the
reaching one is planned, timed and certified by the planner `plan` uses, with the base at
its goal. The arm's trajectory holds still until the base has arrived.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from armcli.drive.diffdrive import DriveParams
from armcli.errors import PlanningError
from armcli.plan.api import (
    PlanningContext,
    PlanOptions,
    PlanResult,
    plan_motion,
    planning_context,
)
from armcli.plan.collision import CollisionChecker
from armcli.plan.inputs import configuration
from armcli.plan.mobile.basepath import BasePath, FloorPlan, plan_base_path
from armcli.plan.mobile.basetime import BaseTiming, time_path
from armcli.plan.mobile.footprint import obstacles, robot_outline
from armcli.plan.mobile.judge import Verdict
from armcli.plan.mobile.place import TOLERANCE, Placement, place
from armcli.plan.mobile.virtual import MobileRobot
from armcli.plan.mobile.wheels import axle_offset, drive_limits, drive_params, to_axle, to_base
from armcli.plan.timing import Timed

HOME = "home"
RAMP_IN = 0.01  # [s] the arm's trajectory enters its first acceleration over this
CERTIFY_STEP = 0.01  # [m or rad] the 3-D check along the base path
MAX_PATHS = 6  # placements whose base path is tried before giving up
NEAR_FAILED = (0.15, math.radians(30.0))  # [m, rad] a pose this near one without a path is skipped


@dataclass(frozen=True)
class BaseGoal:
    """What `plan --base` is asked: the tool's target, the base's start, the arm's start."""

    target: tuple[float, float, float]  # [m] world
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m, m, rad] the base's pose
    arm_start: str | None = None  # a named pose or values; None: `home` (else the rest)
    tolerance: float = TOLERANCE


@dataclass(frozen=True)
class WholePlan:
    """The placement, the base's path and its timing, and the arm's certified motion."""

    mobile: MobileRobot
    drive: DriveParams
    placement: Placement
    path: BasePath
    timing: BaseTiming
    travel: np.ndarray  # the arm during the drive [rad or m]
    arm: PlanResult  # at the base's goal, from `travel` to the placement's configuration
    base_planning_time_s: float  # placement, path and timing (not the certification)
    base_certify_time_s: float
    goal: BaseGoal
    axle: np.ndarray  # (x, y) [m] the wheels' midpoint in the base frame: the path's point
    floor: FloorPlan

    @property
    def arm_timed(self) -> Timed:
        """The arm's trajectory on the whole plan's clock: held until the base has arrived.

        Two held points (at 0 and RAMP_IN before the arm's first): the interpolation between
        the second and the arm's first (which starts at TOPP-RA's first acceleration) is
        then RAMP_IN long, not the whole drive (a quintic over seconds to a non-zero
        acceleration swings far).
        """
        t0 = self.timing.duration
        a = self.arm.timed
        n = a.positions.shape[1]
        hold = [0.0, max(t0 - RAMP_IN, 0.0)] if t0 > RAMP_IN else [0.0]
        k = len(hold)
        return Timed(
            np.concatenate([hold, a.times + t0]),
            np.vstack([np.repeat(self.travel[None, :], k, axis=0), a.positions]),
            np.vstack([np.zeros((k, n)), a.velocities]),
            np.vstack([np.zeros((k, n)), a.accelerations]),
        )


def _travel(mobile: MobileRobot, arm_start: str | None) -> np.ndarray:
    """The arm's configuration while the base drives: the start pose, `home` by default."""
    ctx = PlanningContext(mobile.arm_robot(), mobile.checker)  # names and values only
    if arm_start is None:
        robot = ctx.robot
        if HOME in robot.poses:
            return robot.pose(HOME)
        return np.array([robot.robot.rest(j) for j in robot.joints])
    return configuration(ctx, arm_start, "start")


class _Paths:
    """The placement's `accept`: a pose is taken when a base path to it is found (cached)."""

    def __init__(
        self,
        plan: FloorPlan,
        start: tuple[float, float, float],
        half: float,
        seed: int,
        axle: np.ndarray,
    ) -> None:
        self.plan, self.half, self.seed, self.axle = plan, half, seed, axle
        self.start = to_axle(start, axle)
        self.found: dict[tuple[float, float, float], BasePath] = {}
        self.failed: list[tuple[float, float, float]] = []

    def __call__(self, v: Verdict) -> bool:
        near_xy, near_yaw = NEAR_FAILED
        for f in self.failed:
            if (
                math.dist(f[:2], v.base[:2]) < near_xy
                and abs(math.remainder(f[2] - v.base[2], 2 * math.pi)) < near_yaw
            ):
                return False
        if len(self.failed) >= MAX_PATHS:
            raise PlanningError(
                "base-path",
                f"no base path reaches any of the {MAX_PATHS} best poses that serve the target",
            )
        try:
            self.found[v.base] = plan_base_path(
                self.plan, self.start, to_axle(v.base, self.axle), self.half, self.seed
            )
        except PlanningError:
            self.failed.append(v.base)
            return False
        return True


def _certify(mobile: MobileRobot, timing: BaseTiming, travel: np.ndarray, axle: np.ndarray) -> None:
    """Every turn and leg checked by the 3-D collision checker, CERTIFY_STEP apart.

    The plan is the wheels' midpoint's; the robot checked is the base frame's pose, which
    swings around that point in a turn (sampled finely, each short chord checked).
    """
    checker: CollisionChecker = mobile.checker
    for m in timing.motions:
        scale = timing.limits.half_track if m.kind == "turn" else 1.0
        n = max(1, math.ceil(abs(m.amount) * max(scale, 0.5) / CERTIFY_STEP))
        t = np.linspace(0.0, m.duration, n + 1)
        poses = to_base(m.pose_at(t), axle)
        xs = [mobile.x(p, travel) for p in poses]
        if any(not checker.motion_free(a, b, CERTIFY_STEP) for a, b in itertools.pairwise(xs)):
            where = ", ".join(f"{v:.3f}" for v in poses[0])
            raise PlanningError(
                "certify",
                f"the base path collides in its 3-D check ({m.kind} "
                f"from {where}): the floor plan missed an object",
            )


@dataclass(frozen=True)
class Drive:
    """Where the base parks, its path there and its timing, certified."""

    params: DriveParams
    placement: Placement
    path: BasePath
    timing: BaseTiming
    travel: np.ndarray
    planning_time_s: float  # placement, path and timing
    certify_time_s: float
    goal: BaseGoal
    axle: np.ndarray  # (x, y) [m] the wheels' midpoint in the base frame: the path's point
    floor: FloorPlan  # what the path was planned on (the wheels' midpoint's frame)


def plan_drive(mobile: MobileRobot, goal: BaseGoal, seed: int = 0) -> Drive:
    """Where to park and the certified, timed path there (see the module docstring)."""
    params = drive_params(mobile)
    travel = _travel(mobile, goal.arm_start)
    limits = drive_limits(mobile, params, travel)
    axle = axle_offset(mobile, params)
    outline, top = robot_outline(mobile, travel, axle)
    floor = FloorPlan(outline, obstacles(mobile, top))
    t0 = time.perf_counter()
    paths = _Paths(floor, goal.start, limits.half_track, seed, axle)
    placement = place(
        mobile,
        goal.target,
        goal.start,
        tolerance=goal.tolerance,
        seed=seed,
        park=lambda pose: floor.free(to_axle(pose, axle)),
        accept=paths,
    )
    path = paths.found[placement.verdict.base]
    timing = time_path(path, limits)
    t1 = time.perf_counter()
    _certify(mobile, timing, travel, axle)
    return Drive(
        params,
        placement,
        path,
        timing,
        travel,
        t1 - t0,
        time.perf_counter() - t1,
        goal,
        axle,
        floor,
    )


def plan_whole(mobile: MobileRobot, goal: BaseGoal, options: PlanOptions) -> WholePlan:
    """Place, drive, reach (see the module docstring); PlanningError when any step fails."""
    d = plan_drive(mobile, goal, options.seed)
    ctx = planning_context(
        mobile.arm_robot(d.placement.verdict.base), mobile.world, mobile.disabled
    )
    try:
        arm = plan_motion(ctx, d.travel, d.placement.verdict.q, options)
    except PlanningError as exc:  # say which half failed: the base's plan stands
        x, y, yaw = d.placement.verdict.base
        raise PlanningError(
            exc.kind,
            f"the arm, with the base parked at ({x:.3f}, {y:.3f}) m, "
            f"{math.degrees(yaw):.1f} deg: {exc.reason}",
            pair=exc.pair,
        ) from exc
    return WholePlan(
        mobile,
        d.params,
        d.placement,
        d.path,
        d.timing,
        d.travel,
        arm,
        d.planning_time_s,
        d.certify_time_s,
        goal,
        d.axle,
        d.floor,
    )


def files(plan: WholePlan, out_dir: Path, comment: str) -> dict[Path, bytes]:
    """arm.yaml, cmd_vel.yaml and path.yaml of the plan, by path under `out_dir`."""
    from armcli.plan.mobile.basefiles import cmd_vel_yaml, path_yaml
    from armcli.plan.output import trajectory_yaml

    root = plan.mobile.robot_file.robot
    children = {j.child for j in root.joints}
    frame = next((lk.name for lk in root.links if lk.name not in children), "")
    return {
        out_dir / "arm.yaml": trajectory_yaml(
            plan.mobile.arm, plan.arm_timed, frame_id=frame, comment=comment
        ),
        out_dir / "cmd_vel.yaml": cmd_vel_yaml(plan.timing, comment),
        out_dir / "path.yaml": path_yaml(plan.timing, plan.axle, comment),
    }
