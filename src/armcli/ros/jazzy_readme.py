"""README.md of the Jazzy bringup package: how to run it, and what was never run.

The course drove the arm with `ros2 topic pub /set_joint_trajectory ...`; on Jazzy the
same motion goes to the JointTrajectoryController, by action (with feedback and a
result) or by topic. The commands are written with the spec's joint names and
its first named pose, so they can be pasted as they are.
"""

from __future__ import annotations

import math

from armcli.analysis.rate import round_up
from armcli.compiler.xmlfmt import fmt
from armcli.ros.controller_rate import Control
from armcli.ros.jazzy import GZ_PLUGIN_NAME, MOCK_ARG, controllers_file
from armcli.ros.moveit import ARM_CONTROLLER
from armcli.ros.srdf import chain_joints
from armcli.spec.model import RobotSpec

MOVE_TIME = 2  # [s] time_from_start of the example point


def _example_pose(spec: RobotSpec) -> tuple[str, list[float]]:
    joints = chain_joints(spec)
    names = [p for p in spec.poses if p != "home"] or list(spec.poses)
    if not names:
        return "zero", [0.0] * len(joints)
    pose = spec.pose(names[0])
    return names[0], [pose.get(j, 0.0) for j in joints]


def _trajectory(spec: RobotSpec) -> str:
    _, q = _example_pose(spec)
    joints = ", ".join(chain_joints(spec))
    positions = ", ".join(fmt(v) for v in q)
    return (
        f"{{joint_names: [{joints}], points: [{{positions: [{positions}], "
        f"time_from_start: {{sec: {MOVE_TIME}}}}}]}}"
    )


def _gains_table(spec: RobotSpec, control: Control | None) -> list[str]:
    """The gains as the controllers YAML has them (the integral term of ros/holding.py too)."""
    holding = control.holding if control is not None else {}
    rows = ["| joint | p [N·m/rad] | d [N·m·s/rad] | i [N·m/(rad·s)] |", "|---|---|---|---|"]
    for j in chain_joints(spec):
        g = spec.control.gains[j]
        i = holding[j].i if j in holding else g.ki
        rows.append(f"| {j} | {fmt(g.kp)} | {fmt(g.kd)} | {fmt(i)} |")
    return rows


def _rate(spec: RobotSpec, control: Control | None) -> list[str]:
    """How far the controller's rate is from the edge of its loop (analysis.zoh)."""
    v = control.rate if control is not None else None
    if v is None:
        return []
    hold = f"{fmt(round(v.hold * 1e3, 6))} ms"
    least = f"update_rate >= {round_up(v.rate_min, 3):g} Hz"
    edge = (
        "any hold" if math.isinf(v.hold_max) else f"a hold up to {v.hold_max * 1e3:.3g} ms, {least}"
    )
    return [
        f"gz_ros2_control updates the controller every {hold} and holds its effort in between; "
        f"with these gains that loop is stable for {edge} (`armcli check`: "
        "ros-controller-unstable). A lower `control.controller_update_rate` or stiffer gains "
        "beyond it make the arm oscillate or diverge.",
        "",
    ]


def _moving(spec: RobotSpec) -> list[str]:
    pose, _ = _example_pose(spec)
    ctl = f"/{ARM_CONTROLLER}"
    return [
        "## Moving the arm (the course's `/set_joint_trajectory`)",
        "",
        "The course teleported the joints through `/set_joint_trajectory`. Here the "
        f"trajectory controller tracks it with the spec's gains. To the `{pose}` pose, "
        "by action (feedback and a result):",
        "",
        "```sh",
        f"ros2 action send_goal {ctl}/follow_joint_trajectory "
        f'control_msgs/action/FollowJointTrajectory "{{trajectory: {_trajectory(spec)}}}"',
        "```",
        "",
        "or by topic, as the course did (no result):",
        "",
        "```sh",
        f"ros2 topic pub --once {ctl}/joint_trajectory trajectory_msgs/msg/JointTrajectory "
        f'"{_trajectory(spec)}"',
        "```",
        "",
    ]


def _control(spec: RobotSpec, control: Control | None) -> list[str]:
    tol = spec.control.tolerances
    return [
        "## Control",
        "",
        f"`config/{controllers_file(spec.name)}`: controller_manager at "
        f"{fmt(spec.control.controller_update_rate)} Hz, a JointTrajectoryController on the "
        "**effort** interface. Its torque is `p (q_ref - q) + d (v_ref - v) + i ∫e` "
        "(`ff_velocity_scale` 0), the PD loop `armcli check` bounds and `armcli simulate` runs:",
        "",
        *_gains_table(spec, control),
        "",
        *_rate(spec, control),
        f"Constraints (spec `control.tolerances`): goal {fmt(tol.goal)} rad, trajectory "
        f"{fmt(tol.trajectory)} rad (0 = not checked), goal_time {fmt(tol.goal_time)} s, "
        f"stopped_velocity_tolerance {fmt(tol.stopped_velocity_tolerance)} rad/s. Without "
        "integral action the arm settles off its goal by gravity torque / p; "
        "`armcli check` prints the worst gravity torque per joint.",
        "",
        f"`{MOCK_ARG}:=true` (xacro argument) swaps gz_ros2_control for "
        "`mock_components/GenericSystem` to test the wiring without Gazebo; mock hardware "
        "only mirrors commands, so an effort command does not move the joints there.",
        "",
    ]


NOT_RUN = [
    "## What was not run",
    "",
    "armcli generated these files without a ROS installation. Checked by its tests: "
    "the launch files compile and name only packages in package.xml; every YAML parses "
    "and names only joints of the URDF; the expanded xacro passes `check_urdf`, "
    "`armcli check` and Pinocchio; package.xml validates with catkin_pkg. **Not run**: "
    "a real ROS 2 Jazzy + Gazebo Harmonic install, i.e. `colcon build`, the launch "
    f"itself, {GZ_PLUGIN_NAME} loading the controllers, and the tracking in Gazebo "
    "(Gazebo's physics differs from armcli's simulator: contacts, its own integrator).",
    "",
]


def readme(
    spec: RobotSpec, bringup: str, launch: str, moveit: str, note: str, control: Control | None
) -> bytes:
    """The whole README text, deterministic for a given spec (and its `control`)."""
    lines = [
        f"# {bringup}: {spec.name} in Gazebo Harmonic with ros2_control (ROS 2 Jazzy)",
        "",
        note,
        "",
        "## Run",
        "",
        "```sh",
        f"ros2 launch {bringup} {launch}                   # whole robot",
        f"ros2 launch {bringup} {launch} standalone:=true  # the arm alone",
        f"ros2 launch {moveit} gz_move_group.launch.py     # optional: MoveIt on top",
        "```",
        "",
        "The launch starts `gz_sim.launch.py` (ros_gz_sim) with an empty world, "
        "robot_state_publisher on the xacro, `ros_gz_sim create -topic robot_description`, "
        f"the ros_gz_bridge of `/clock` and the sensor topics (`config/{spec.name}_bridge.yaml`), "
        "then spawns `joint_state_broadcaster` once the robot exists "
        f"and `{ARM_CONTROLLER}` once that is active.",
        "",
        *_moving(spec),
        *_control(spec, control),
        *NOT_RUN,
    ]
    return "\n".join(lines).encode("utf-8")
