"""The ROS 2 Jazzy + Gazebo Harmonic parts of `ros-package --target jazzy`.

The course target teleports the arm (Gazebo classic's joint_pose_trajectory
plugin), so the spec's gains never reach the simulator. Here the arm is driven
by ros2_control: gz_ros2_control exposes an **effort** command interface per arm
joint and a JointTrajectoryController closes the loop with the spec's PD gains,
so what `check` and `simulate` said about those gains is what runs in Gazebo.

This module only builds content (xacro trees, controller YAML data, launch
files); `ros_package` puts it into packages. The course xacro parts
(common_properties, arm, mobile_base) are included unchanged; the classic
`*_gazebo.xacro` files are not, because their plugins do not exist in gz-sim.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import yaml
from lxml import etree

from armcli.compiler.ros2_control import joint_block
from armcli.compiler.sensors import bridge_entries, harmonic_sensor, harmonic_systems
from armcli.compiler.xacro_writer import (
    ARM,
    COMMON,
    MOBILE_BASE,
    WORLD,
    WORLD_JOINT,
    has_base,
    joint_element,
)
from armcli.compiler.xmlfmt import XACRO_NS, fmt, to_bytes
from armcli.errors import InputError
from armcli.ros import interfaces
from armcli.ros import moveit as mc
from armcli.ros.holding import START_TOLERANCE, Integral
from armcli.ros.interfaces import GAIN_INTERFACES, JAZZY
from armcli.ros.launch import render
from armcli.ros.srdf import chain_joints
from armcli.spec.model import Joint, RobotSpec, Sensor

X = f"{{{XACRO_NS}}}"
GZ_SYSTEM = "gz_ros2_control/GazeboSimSystem"
MOCK_SYSTEM = "mock_components/GenericSystem"
GZ_PLUGIN_FILE = "gz_ros2_control-system"
GZ_PLUGIN_NAME = "gz_ros2_control::GazeboSimROS2ControlPlugin"
DIFF_DRIVE_FILE = "gz-sim-diff-drive-system"
DIFF_DRIVE_NAME = "gz::sim::systems::DiffDrive"
MOCK_ARG = "use_mock_hardware"
CONTROLLERS_ARG = "controllers_file"
JTC_TYPE = "joint_trajectory_controller/JointTrajectoryController"
JSB_TYPE = "joint_state_broadcaster/JointStateBroadcaster"
TOP = "{name}_gz.urdf.xacro"
STANDALONE = "standalone_arm_gz.urdf.xacro"
GZ_LAUNCH = "{name}_gz.launch.py"
MOVE_GROUP_LAUNCH = "gz_move_group.launch.py"
# Everything the Jazzy bringup launch starts or loads, for its package.xml.
BRINGUP_DEPENDS = [
    "ament_index_python",
    "control_msgs",
    "controller_manager",
    "gz_ros2_control",
    "joint_state_broadcaster",
    "joint_trajectory_controller",
    "launch",
    "launch_ros",
    "robot_state_publisher",
    "ros_gz_bridge",
    "ros_gz_sim",
    "rviz2",
    "trajectory_msgs",
    "xacro",
]
# control_msgs, trajectory_msgs: the README's send_goal / topic pub commands need them.
MOVEIT_DEPENDS = ["launch", "launch_ros"]  # gz_move_group.launch.py imports them
# What MoveIt waits for at the end of a trajectory (MoveIt's own defaults, written out).
EXECUTION = {
    "allowed_execution_duration_scaling": 1.2,
    "allowed_goal_duration_margin": 0.5,
    "allowed_start_tolerance": START_TOLERANCE,
}


def controllers_file(robot: str) -> str:
    """File name of the controllers YAML in the bringup's `config/`."""
    return f"{robot}_controllers.yaml"


def _robot(name: str) -> etree._Element:
    return etree.Element("robot", {"name": name}, nsmap={"xacro": XACRO_NS})


def _sub(parent: etree._Element, tag: str, text: str | None = None, **attrs: str) -> etree._Element:
    el = etree.SubElement(parent, tag, attrs)
    if text is not None:
        el.text = text
    return el


def required_gains(spec: RobotSpec, source: str | None = None) -> dict[str, Any]:
    """Every commanded joint needs gains: an effort JTC without them applies no torque.

    A position-commanded arm (the spec's ros2_control says so) needs none: {}.
    """
    joints = chain_joints(spec)
    if interfaces.trajectory_interface(spec, joints, JAZZY, source) not in GAIN_INTERFACES:
        return {}
    missing = [j for j in joints if j not in spec.control.gains]
    if missing:
        raise InputError(
            f"the jazzy target drives the arm by effort and needs gains for every arm joint; "
            f"missing: {', '.join(missing)}",
            file=source,
            field="control.gains",
        )
    return {j: spec.control.gains[j] for j in joints}


def _hardware(rc: etree._Element) -> None:
    hw = _sub(rc, "hardware")
    mock = _sub(hw, X + "if", value=f"$(arg {MOCK_ARG})")
    _sub(mock, "plugin", MOCK_SYSTEM)
    gz = _sub(hw, X + "unless", value=f"$(arg {MOCK_ARG})")
    _sub(gz, "plugin", GZ_SYSTEM)


def ros2_control_block(parent: etree._Element, spec: RobotSpec, passive: list[str]) -> None:
    """`<ros2_control>`: the arm joints' interfaces (ros.interfaces), state for `passive`.

    Unless the spec says otherwise an arm joint takes effort within its effort limit and
    reports position, velocity and effort. The position state starts at the `home` pose
    (mc.initial_positions), which gz_ros2_control also uses to place the joints at spawn.
    """
    rc = _sub(parent, "ros2_control", name=f"{spec.name}_system", type="system")
    _hardware(rc)
    start = mc.initial_positions(spec)["initial_positions"]
    for name in chain_joints(spec):
        joint_block(rc, name, interfaces.commanded(spec, name, JAZZY), fmt(start[name]))
    for name in passive:
        joint_block(rc, name, interfaces.passive(spec, name))


def _gz_plugins(parent: etree._Element, spec: RobotSpec, whole: bool) -> None:
    """gz_ros2_control's system plugin (and the base's DiffDrive), only outside mock mode."""
    sim = _sub(parent, X + "unless", value=f"$(arg {MOCK_ARG})")
    plugin = _sub(_sub(sim, "gazebo"), "plugin", filename=GZ_PLUGIN_FILE, name=GZ_PLUGIN_NAME)
    _sub(plugin, "parameters", f"$(arg {CONTROLLERS_ARG})")
    dd = spec.mobile_base.diff_drive if spec.mobile_base is not None else None
    if whole and dd is not None:
        p = _sub(_sub(sim, "gazebo"), "plugin", filename=DIFF_DRIVE_FILE, name=DIFF_DRIVE_NAME)
        for key, value in (
            ("left_joint", dd.left_joint),
            ("right_joint", dd.right_joint),
            ("wheel_separation", fmt(dd.wheel_separation)),
            ("wheel_radius", fmt(dd.wheel_diameter / 2)),
            ("odom_publish_frequency", fmt(dd.update_rate)),
            ("topic", "cmd_vel"),
            ("odom_topic", "odom"),
            ("frame_id", dd.odometry_frame),
            ("child_frame_id", dd.robot_base_frame),
        ):
            _sub(p, key, value)


def _friction(parent: etree._Element, spec: RobotSpec, whole: bool) -> None:
    links = spec.all_links() if whole else dict(spec.arm.links)
    for name, link in links.items():
        if link.contact is not None:
            gz = _sub(parent, "gazebo", reference=name)
            _sub(gz, "mu1", fmt(link.contact.mu1))
            _sub(gz, "mu2", fmt(link.contact.mu2))


def top_xacro(spec: RobotSpec, bringup_pkg: str, *, whole: bool, header: str) -> bytes:
    """A Jazzy top-level xacro: the course parts plus ros2_control and gz-sim plugins.

    The arm alone is welded to a `world` link (gz-sim fixes a model to the world
    through a link of that name); otherwise its torque-driven links would topple
    the light arm base over in Gazebo.
    """
    root = _robot(spec.name if whole else "standalone_arm")
    _sub(root, X + "arg", name=MOCK_ARG, default="false")
    default = f"$(find {bringup_pkg})/config/{controllers_file(spec.name)}"
    _sub(root, X + "arg", name=CONTROLLERS_ARG, default=default)
    parts = [COMMON, MOBILE_BASE, ARM] if whole else [COMMON, ARM]
    for inc in parts:
        _sub(root, X + "include", filename=inc)
    if whole and spec.mounted_base() is not None:
        joint_element(root, spec.mount_joint_name(), spec.mount_joint())
    if not whole:
        _sub(root, "link", name=WORLD)
        anchor = Joint(type="fixed", parent=WORLD, child=spec.arm_root())
        joint_element(root, WORLD_JOINT, anchor)
    _friction(root, spec, whole)
    ros2_control_block(root, spec, mc.passive_joints(spec) if whole else [])
    _gz_plugins(root, spec, whole)
    _sensors(root, spec, whole)
    return to_bytes(root, header_comment=header)


def sensors_on(spec: RobotSpec, whole: bool) -> dict[str, Sensor]:
    """The sensors of the whole robot, or of the arm alone."""
    links = spec.all_links() if whole else spec.arm.links
    return {n: s for n, s in spec.sensors.items() if s.link in links}


def _sensors(root: etree._Element, spec: RobotSpec, whole: bool) -> None:
    """gz-sim sensors and the systems that run them (outside mock mode, like the plugins)."""
    sensors = sensors_on(spec, whole)
    if not sensors:
        return
    sim = _sub(root, X + "unless", value=f"$(arg {MOCK_ARG})")
    for el in harmonic_systems(list(sensors.values())):
        sim.append(el)
    for name, s in sensors.items():
        sim.append(harmonic_sensor(name, s))


def bridge_file(robot: str) -> str:
    """File name of the ros_gz_bridge configuration in the bringup's `config/`."""
    return f"{robot}_bridge.yaml"


def bridge(spec: RobotSpec) -> list[dict[str, Any]]:
    """ros_gz_bridge entries: the simulation clock, then every sensor's topics."""
    out: list[dict[str, Any]] = [
        {
            "ros_topic_name": "clock",
            "gz_topic_name": "clock",
            "ros_type_name": "rosgraph_msgs/msg/Clock",
            "gz_type_name": "gz.msgs.Clock",
            "direction": "GZ_TO_ROS",
        }
    ]
    for s in spec.sensors.values():
        out += bridge_entries(s)
    return out


def bridge_yaml(spec: RobotSpec, note: str) -> bytes:
    """ros_gz_bridge's config file: a YAML list of topic entries (`bridge`)."""
    body = yaml.dump(bridge(spec), Dumper=mc.Dumper, sort_keys=False, default_flow_style=False)
    return ("".join(f"# {line}\n" for line in note.splitlines()) + body).encode("utf-8")


def description_xacros(spec: RobotSpec, bringup_pkg: str, header: str) -> dict[str, bytes]:
    """urdf/ name -> bytes of the Jazzy top-level xacro files."""
    out = {STANDALONE: top_xacro(spec, bringup_pkg, whole=False, header=header)}
    if has_base(spec):
        out[TOP.format(name=spec.name)] = top_xacro(spec, bringup_pkg, whole=True, header=header)
    return out


def controllers(
    spec: RobotSpec,
    source: str | None = None,
    holding: Mapping[str, Integral] | None = None,
) -> dict[str, Any]:
    """controller_manager + joint_state_broadcaster + an effort JointTrajectoryController.

    JTC's effort law is `ff_velocity_scale * v_ref + PID(q_ref - q, v_ref - v)`; with
    ff_velocity_scale 0 and PID gains p = Kp, d = Kd, i = Ki this is the spec's
    `Kp (q_ref - q) + Kd (v_ref - v) [+ Ki integral]`, the loop `simulate` runs.
    `holding` (ros/holding.py) adds the integral term that keeps the arm at its named
    poses when the spec's PD alone sags more than MoveIt's start tolerance. i_clamp bounds
    the integral torque by the effort limit (0 without an integral term).
    """
    gains = required_gains(spec, source)
    chain = chain_joints(spec)
    command = interfaces.trajectory_interface(spec, chain, JAZZY, source)
    joints = spec.all_joints()
    tol = spec.control.tolerances
    constraints: dict[str, Any] = {
        "stopped_velocity_tolerance": float(tol.stopped_velocity_tolerance),
        "goal_time": float(tol.goal_time),
    }
    pid: dict[str, Any] = {}
    for name in chain:
        constraints[name] = {"trajectory": float(tol.trajectory), "goal": float(tol.goal)}
    for name, g in gains.items():
        lim = joints[name].limit
        clamp = float(lim.effort) if (lim is not None and g.ki > 0) else 0.0
        extra = (holding or {}).get(name)
        pid[name] = {
            "p": float(g.kp),
            "d": float(g.kd),
            "i": float(extra.i if extra is not None else g.ki),
            "i_clamp": float(extra.i_clamp) if extra is not None else clamp,
            "ff_velocity_scale": 0.0,
        }
    arm: dict[str, Any] = {
        "joints": chain,
        "command_interfaces": [command],
        "state_interfaces": ["position", "velocity"],
        "allow_nonzero_velocity_at_trajectory_end": False,
        "constraints": constraints,
    }
    if pid:
        arm["gains"] = pid
    return {
        "controller_manager": {
            "ros__parameters": {
                "update_rate": mc.controller_update_rate(spec, source),
                mc.ARM_CONTROLLER: {"type": JTC_TYPE},
                mc.JOINT_STATE_BROADCASTER: {"type": JSB_TYPE},
            }
        },
        mc.ARM_CONTROLLER: {"ros__parameters": arm},
    }


def moveit_controllers(spec: RobotSpec) -> dict[str, Any]:
    """MoveIt -> the JTC's `follow_joint_trajectory` action, plus execution monitoring."""
    out = mc.moveit_controllers(spec)
    return {"trajectory_execution": dict(EXECUTION), **out}


def bringup_launch(values: dict[str, str], note: str) -> bytes:
    """The Gazebo Harmonic launch file, checked to compile by `render`."""
    return render("gz_sim.launch.py.tmpl", values, note)


def move_group_launch(robot: str, moveit_pkg: str, note: str) -> bytes:
    """move_group + RViz on simulated time, for the arm running in Gazebo."""
    values = {"robot": robot, "moveit_pkg": moveit_pkg}
    return render("gz_move_group.launch.py.tmpl", values, note)
