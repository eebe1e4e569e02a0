"""The planning panel's mobile base, without a browser: a target anywhere, plan, execute.

For a robot on a differential drive: the target is a point anywhere in the room; **Plan**
is `plan --base` (plan.mobile.whole: where to park, the drive there, the arm) and gives
what the panel draws: the base path, the floor positions from which the target is in
reach (the feasible region), the arm's ghosts at the parked pose; **Execute** is
`--execute` (plan.mobile.execute, the MuJoCo drive) and its run, whole robot, to replay.
The viser layer is view.basepanel.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from armcli.errors import ArmcliError, InputError
from armcli.plan.api import PlanOptions
from armcli.plan.mobile.execute import Executed, execute_whole
from armcli.plan.mobile.judge import Judge
from armcli.plan.mobile.place import turn_radius
from armcli.plan.mobile.placeplot import serving
from armcli.plan.mobile.virtual import MobileRobot, load_mobile
from armcli.plan.mobile.wheels import drive_params, to_base
from armcli.plan.mobile.whole import BaseGoal, WholePlan, files, plan_whole
from armcli.sim.states import Replay
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile

GHOSTS = 5  # arm ghosts along the arm's motion at the parked pose, both ends included
PATH_POINTS = 200  # base poses drawn along the path


@dataclass(frozen=True)
class BaseDrawing:
    """What Plan draws: the base path and region on the floor, the parked pose, the ghosts."""

    path: np.ndarray  # (P, 3) base frame positions [m] along the drive (z 0)
    region: np.ndarray  # (R, 2) floor positions [m] from which the target is in reach
    parked: tuple[float, float, float]  # (x, y, yaw) [m, m, rad]
    ghosts: tuple[np.ndarray, ...]  # the arm's configurations along its motion


class BaseSession:
    """A drive plan for one robot among one scene's objects; the last plan and execution."""

    def __init__(self, mobile: MobileRobot, options: PlanOptions | None = None) -> None:
        self.mobile = mobile
        self.options = options or PlanOptions()
        self.plan: WholePlan | None = None
        self.reason: str | None = None
        self.execution: Executed | None = None

    @property
    def arm(self) -> tuple[str, ...]:
        """The arm's joints (what the ghosts set)."""
        return self.mobile.arm

    def plan_to(self, target: tuple[float, float, float]) -> BaseDrawing | None:
        """Plan the base and the arm to reach `target` [m] from the origin; None: `reason`."""
        self.plan, self.reason, self.execution = None, None, None
        try:
            self.plan = plan_whole(self.mobile, BaseGoal(target), self.options)
        except ArmcliError as exc:
            self.reason = str(exc)
            return None
        return self.drawing()

    def drawing(self) -> BaseDrawing:
        """The last plan's path, region, parked pose and arm ghosts."""
        plan = self._need_plan()
        t = np.linspace(0.0, plan.timing.duration, PATH_POINTS)
        poses = to_base(plan.timing.pose_at(t), plan.axle)
        path = np.column_stack([poses[:, :2], np.zeros(len(t))])
        judge = Judge(self.mobile, plan.goal.target, plan.goal.tolerance)
        region = serving(judge, plan.goal.start, turn_radius(self.mobile))
        a = plan.arm.timed
        at = np.linspace(float(a.times[0]), float(a.times[-1]), GHOSTS)
        ghosts = tuple(
            np.array(
                [np.interp(tk, a.times, a.positions[:, i]) for i in range(a.positions.shape[1])]
            )
            for tk in at
        )
        return BaseDrawing(path, region, plan.placement.verdict.base, ghosts)

    def execute(self) -> Executed:
        """Run the last plan on the MuJoCo drive (its files in a temporary directory)."""
        plan = self._need_plan()
        with tempfile.TemporaryDirectory(prefix="armcli-view-") as tmp:
            out = Path(tmp)
            written = files(plan, out, "armcli view")
            for path, data in written.items():
                path.write_bytes(data)
            self.execution = execute_whole(plan, out / "cmd_vel.yaml", written[out / "arm.yaml"])
        return self.execution

    def replay(self) -> Replay:
        """The last execution, whole robot: the arm's and wheels' joints, the root's pose."""
        done = self.execution
        if done is None:
            raise InputError("nothing executed yet: click Execute first", field="execute")
        run = done.run
        L, s = run.job.model.layout, run.sensors
        names = [*run.job.arm.robot.names, run.job.params.left_joint, run.job.params.right_joint]
        cols = np.column_stack([s[:, L.arm_pos], s[:, L.wheel_pos]])
        step = max(1, len(run.t) // 2000)
        position = {n: cols[::step, i].copy() for i, n in enumerate(names)}
        base = np.column_stack([s[::step, L.base_pos], s[::step, L.base_quat]])
        return Replay("<execute>", run.t[::step].copy(), position, {}, base)

    def status(self) -> str:
        """One line on the last plan or execution."""
        if self.plan is None:
            return f"no plan: {self.reason}" if self.reason else "drag the room target, then Plan"
        v, t = self.plan.placement.verdict, self.plan.timing
        line = (
            f"parks at ({v.base[0]:.2f}, {v.base[1]:.2f}) m, {math.degrees(v.base[2]):.0f}°: "
            f"{self.plan.path.length:.2f} m in {t.duration:.1f} s, then the arm "
            f"{self.plan.arm.duration_s:.1f} s"
        )
        done = self.execution
        if done is not None:
            line += f"; executed: tool {done.tool_error * 1e3:.1f} mm from the target"
            line += f", {done.problems[0]}" if done.problems else ""
        return line

    def _need_plan(self) -> WholePlan:
        if self.plan is None:
            raise InputError("nothing planned yet: click Plan first", field="plan")
        return self.plan


def load_base_session(
    robot_file: RobotFile, scene: Path | None = None, search: MeshSearch | None = None
) -> BaseSession | None:
    """A base session for a robot with a diff drive (None without one: no base to drive)."""
    mobile = load_mobile(robot_file, scene=scene, search=search)
    try:
        drive_params(mobile)
    except InputError:
        return None
    return BaseSession(mobile)
