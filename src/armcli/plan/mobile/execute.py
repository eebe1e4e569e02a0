"""`plan --base --execute`: the whole plan on the MuJoCo drive, followed on the encoders, judged.

The drive (`drive.job`: the robot as `export mjcf` writes it, gazebo_ros_diff_drive's
controller and wheel motor, the arm's PD loop with gravity compensation) runs among the
scene's objects (`sim.world`, the scene moved into the frame the robot starts in: MuJoCo's
origin), the base steered by the path follower (`plan.mobile.pursuit`) on the plugin's
encoder odometry, the arm's trajectory held until the base has arrived. Judged on the
ground truth: the tool's final distance to the target, the base's final pose against the
plan, the arm's peak efforts and speeds against its limits, the tip-over verdict.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from armcli.analysis.liftoff import TiltVerdict
from armcli.drive import job as drive
from armcli.drive import output as driveout
from armcli.drive.cmdvel import CmdVel
from armcli.drive.job import DriveRun
from armcli.errors import InputError
from armcli.io.scene import Scene, SceneObject
from armcli.plan.mobile.pursuit import Pursuit, legs_in_odom
from armcli.plan.mobile.wheels import to_base
from armcli.plan.mobile.whole import WholePlan
from armcli.robot.frames import quaternion_matrix
from armcli.sim.options import SimOptions
from armcli.sim.simulate import SimResult, steps_of
from armcli.urdf.source import RobotFile

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

TOLERANCE = 0.02  # [m] the tool farther than this from the target on the ground truth: a miss
SLACK = 1.5  # the base may take this many times its planned time (plus SLACK_S) to arrive
SLACK_S = 2.0  # [s]
SETTLE_S = 1.0  # [s] simulated after the arm's last point
LOCALIZE = 10.0  # [Hz] the localiser's rate, plan.mobile.pursuit
STOP_SLACK = 0.005  # [rad or m] MuJoCo's soft joint limits: beyond by more is a broken limit


@dataclass(frozen=True)
class Executed:
    """The run and its verdicts."""

    run: DriveRun
    arm: SimResult
    verdict: TiltVerdict
    tool_error: float  # [m] ground truth, at the end
    base_error: tuple[float, float]  # [m, rad] final pose against the plan (ground truth)
    arrived: float | None  # [s] when the follower had the base at its goal (odometry)
    peak_effort: dict[str, tuple[float, float]]  # joint -> (peak, limit) [N·m or N]
    problems: tuple[str, ...]  # a tip, a broken limit, a miss beyond the tolerance
    odometry: tuple[float, float, float]  # the follower's encoder odometry at the end
    localize: float = 0.0  # [Hz] the localiser stand-in's ground-truth fixes (0: encoders only)

    @property
    def failed(self) -> bool:
        """Whether the execution tipped, broke a limit or missed."""
        return bool(self.problems)


def start_frame(scene: Scene, start: tuple[float, float, float]) -> Scene:
    """The scene's world objects moved into the frame of a base standing at `start`."""
    c, s = math.cos(start[2]), math.sin(start[2])
    T = np.eye(4)
    T[:2, :2] = [[c, s], [-s, c]]
    T[:2, 3] = -T[:2, :2] @ np.array(start[:2])
    objects = []
    for obj in scene.objects:
        if obj.frame:  # fixed to a robot link: moves with it
            objects.append(obj)
            continue
        shapes = tuple(replace(sh, T_frame_shape=T @ sh.T_frame_shape) for sh in obj.shapes)
        objects.append(SceneObject(obj.id, obj.frame, shapes))
    return Scene(tuple(objects), scene.source)


def executable(robot_file: RobotFile) -> RobotSpec:
    """The spec the drive runs; InputError before any planning when there is none to run.

    The drive simulates a spec's `mobile_base` apart from its `arm`: a URDF has no spec,
    and an imported robot whose wheels stayed in its arm (no `mobile_base`) has no base.
    """
    spec = robot_file.spec
    if spec is None:
        raise InputError(
            "drives a spec's robot: `armcli import` writes one from the URDF "
            "(keeping its diff-drive plugin)",
            field="execute",
        )
    if spec.mobile_base is None:
        raise InputError(
            f"drives a spec's mobile_base apart from its arm: {robot_file.path} "
            "has no mobile_base (its arm holds the wheels)",
            field="execute",
        )
    return spec


def execute_whole(
    plan: WholePlan,
    cmd_vel: Path | CmdVel,
    arm_yaml: bytes,
    tolerance: float = TOLERANCE,
    localize: float = LOCALIZE,
) -> Executed:
    """Run the plan (its written cmd_vel.yaml and arm.yaml) on the drive and judge it.

    `cmd_vel`: the file, or the same commands unparsed (`basefiles.cmd_vel_of`): the
    follower steers the base, the file's commands go to the MCAP's /cmd_vel.

    `localize` [Hz]: the localiser's rate (`plan.mobile.pursuit`); 0: encoders alone.
    """
    mobile = plan.mobile
    executable(mobile.robot_file)
    start = plan.goal.start
    duration = SLACK * plan.timing.duration + SLACK_S + plan.arm.duration_s + SETTLE_S
    opts = SimOptions(message=arm_yaml.decode("utf-8"), gravity_comp=True, duration=duration)
    job = drive.prepare(
        mobile.robot_file, opts, cmd_vel, world=start_frame(mobile.scene, start), params=plan.drive
    )
    pilot = Pursuit(
        legs_in_odom(plan.timing, plan.path.start),
        plan.timing.motions,
        radius=job.params.radius,
        separation=job.params.separation,
        dt=job.dt,
        period=job.params.period,
        speed=plan.timing.limits.speed,
        accel=plan.timing.limits.accel,
        wheel_dof=job.model.wheel_dof,
        arrival_step=steps_of(plan.timing.duration, job.dt),
        axle=plan.axle,
        localize=localize,
    )
    run = drive.run(job, pilot=pilot)
    arm = driveout.arm_result(run, driveout.plot_steps_of(run.steps, job.dt, job.arm.rate))
    verdict = driveout.tip_verdict(run)
    return replace(_judge(plan, run, arm, verdict, pilot, tolerance), localize=localize)


def _truth(plan: WholePlan, run: DriveRun) -> tuple[np.ndarray, np.ndarray]:
    """The final base pose (x, y, yaw) and tool point [m], ground truth, in the start frame."""
    L, s = run.job.model.layout, run.sensors[-1]
    p, (w, x, y, z) = s[L.base_pos], s[L.base_quat]
    R = quaternion_matrix((x, y, z, w))
    robot = plan.mobile.arm_robot()
    ran = dict(zip(run.job.arm.robot.names, s[L.arm_pos].tolist(), strict=True))
    tool_b = robot.robot.tool_position(robot.q([ran[j] for j in robot.joints]))
    yaw = math.atan2(R[1, 0], R[0, 0])
    return np.array([p[0], p[1], yaw]), R @ np.asarray(tool_b) + p


def _judge(
    plan: WholePlan,
    run: DriveRun,
    arm: SimResult,
    verdict: TiltVerdict,
    pilot: Pursuit,
    tolerance: float,
) -> Executed:
    start = plan.goal.start
    c, s = math.cos(start[2]), math.sin(start[2])

    def local(x: float, y: float) -> np.ndarray:
        return np.array(
            [c * (x - start[0]) + s * (y - start[1]), -s * (x - start[0]) + c * (y - start[1])]
        )

    goal = plan.placement.verdict.base
    aim = plan.goal.target
    target = np.array([*local(aim[0], aim[1]), aim[2]])
    base, tool = _truth(plan, run)
    base_err = (
        float(np.hypot(*(base[:2] - local(goal[0], goal[1])))),
        abs(math.remainder(base[2] - (goal[2] - start[2]), 2 * math.pi)),
    )
    tool_err = float(np.linalg.norm(tool - target))
    job = run.job
    L, sens = job.model.layout, run.sensors
    names, effort = job.arm.robot.names, job.arm.robot.effort
    peaks = np.max(np.abs(sens[:, L.arm_force]), axis=0)
    problems = []
    if verdict.tips:
        problems.append(verdict.line())
    for i, name in enumerate(names):
        if arm.stats.saturated_steps[i] > 0:
            problems.append(f"{name} reaches its effort limit {effort[i]:g}")
        q = sens[:, L.arm_pos][:, i]
        lo, hi = job.arm.robot.lower[i], job.arm.robot.upper[i]
        if np.any(q < lo - STOP_SLACK) or np.any(q > hi + STOP_SLACK):
            problems.append(f"{name} leaves its range [{lo:g}, {hi:g}] by more than {STOP_SLACK:g}")
    if tool_err > tolerance:
        problems.append(
            f"the tool ends {tool_err * 1e3:.1f} mm from the target (tolerance "
            f"{tolerance * 1e3:g} mm)"
        )
    arrived = None if pilot.arrived is None else pilot.arrived * job.dt
    if arrived is None:
        problems.append("the base did not arrive at its goal in the time given")
    peak = {n: (float(pk), float(e)) for n, pk, e in zip(names, peaks, effort, strict=True)}
    odom = (float(pilot.pose[0]), float(pilot.pose[1]), float(pilot.pose[2]))
    return Executed(run, arm, verdict, tool_err, base_err, arrived, peak, tuple(problems), odom)


def run_files(plan: WholePlan, done: Executed, out_dir: Path) -> dict[Path, bytes]:
    """run.csv (the drive's states columns) and run.mcap (its topics and /plan)."""
    from armcli.drive import bag as drivebag
    from armcli.sim import rosbag, states

    rate = done.run.job.arm.rate
    cols = driveout.columns(done.run, done.arm, rate)
    plan_topic = rosbag.Channel(
        "/plan", "nav_msgs/msg/Path", rosbag.qos(1, True), [(0, plan_message(plan))]
    )
    return {
        out_dir / "run.csv": states.states_bytes(cols, "csv"),
        out_dir / "run.mcap": drivebag.mcap_bytes(done.run, cols, rate, [plan_topic]),
    }


def plan_message(plan: WholePlan) -> dict[str, object]:
    """The planned base path as a nav_msgs/Path in the run's world (the start frame)."""
    from armcli.plan.mobile.basefiles import path_times
    from armcli.sim import rosbag

    start = plan.goal.start
    c, s = math.cos(start[2]), math.sin(start[2])
    t = path_times(plan.timing)
    poses = []
    for tk, (x, y, yaw) in zip(t, to_base(plan.timing.pose_at(t), plan.axle), strict=True):
        dx, dy = x - start[0], y - start[1]
        rel = yaw - start[2]
        ns = round(float(tk) * 1e9)
        poses.append(
            {
                "header": {"stamp": rosbag.stamp(ns), "frame_id": rosbag.WORLD},
                "pose": {
                    "position": {"x": c * dx + s * dy, "y": -s * dx + c * dy, "z": 0.0},
                    "orientation": {
                        "x": 0.0,
                        "y": 0.0,
                        "z": math.sin(rel / 2),
                        "w": math.cos(rel / 2),
                    },
                },
            }
        )
    return {"header": {"stamp": rosbag.stamp(0), "frame_id": rosbag.WORLD}, "poses": poses}
