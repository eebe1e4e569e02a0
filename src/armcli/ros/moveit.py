"""Spec -> the YAML files of a MoveIt 2 config package and its ros2_control controllers.

These are the files the Setup Assistant leaves half-done (second seed): the
kinematics plugin is chosen here (KDL, position-only because a 2-axis arm
cannot reach arbitrary 6-D poses), the controller gains come from the spec
instead of hard-coded PID values, and every joint list is the spec's.
YAML is emitted in a fixed key order with one float formatter.
"""

from __future__ import annotations

from typing import Any

import yaml

from armcli.defaults import DEFAULT_JOINT_ACCELERATION
from armcli.errors import InputError
from armcli.robot.joints import rest
from armcli.ros.interfaces import HUMBLE, trajectory_interface
from armcli.ros.srdf import ARM_GROUP, chain_joints
from armcli.spec.joint_types import position_bounds
from armcli.spec.model import RobotSpec
from armcli.urdf.doc import Urdf

ARM_CONTROLLER = "arm_controller"
JOINT_STATE_BROADCASTER = "joint_state_broadcaster"
KDL_PLUGIN = "kdl_kinematics_plugin/KDLKinematicsPlugin"
IK_SEARCH_RESOLUTION = 0.005  # [rad] Setup Assistant default
IK_TIMEOUT = 0.005  # [s] Setup Assistant default
SCALING_DEFAULT = 0.1  # Setup Assistant default velocity/acceleration scaling


class Dumper(yaml.SafeDumper):
    """Block-style YAML, lists indented under their key like ROS 2 examples."""

    def increase_indent(self, flow: bool = False, indentless: bool = False) -> Any:
        """Indent sequences under their key (never "indentless")."""
        return super().increase_indent(flow, False)


def dump_yaml(data: dict[str, Any], header: str | None = None) -> bytes:
    """Deterministic YAML text: insertion order, block style, optional `#` header."""
    body = yaml.dump(data, Dumper=Dumper, sort_keys=False, default_flow_style=False, width=100)
    head = "".join(f"# {line}\n" for line in header.splitlines()) if header else ""
    return (head + body).encode("utf-8")


def kinematics(spec: RobotSpec) -> dict[str, Any]:
    """The kinematics.yaml of the arm group: KDL, position-only (2 axes cannot reach 6-D poses)."""
    return {
        ARM_GROUP: {
            "kinematics_solver": KDL_PLUGIN,
            "kinematics_solver_search_resolution": IK_SEARCH_RESOLUTION,
            "kinematics_solver_timeout": IK_TIMEOUT,
            "position_only_ik": True,
        }
    }


def joint_limits(urdf: Urdf, joints: list[str]) -> dict[str, Any]:
    """MoveIt joint_limits.yaml: velocity, acceleration and effort limits from the URDF.

    A joint without `<limit acceleration>` gets DEFAULT_JOINT_ACCELERATION, the limit
    `armcli plan` uses for it, so MoveIt and `plan` time motions under the same limits.
    """
    by_name = {j.name: j for j in urdf.joints}
    limits: dict[str, Any] = {}
    for name in joints:
        lim = by_name[name].limit
        vel = lim.velocity if lim is not None else None
        eff = lim.effort if lim is not None else None
        acc = lim.acceleration if lim is not None else None
        limits[name] = {
            "has_velocity_limits": vel is not None,
            "max_velocity": float(vel or 0.0),
            "has_acceleration_limits": True,
            "max_acceleration": float(acc or DEFAULT_JOINT_ACCELERATION),
            "has_effort_limits": eff is not None,
            "max_effort": float(eff or 0.0),
        }
    return {
        "default_velocity_scaling_factor": SCALING_DEFAULT,
        "default_acceleration_scaling_factor": SCALING_DEFAULT,
        "joint_limits": limits,
    }


def controller_update_rate(spec: RobotSpec, source: str | None = None) -> int:
    """controller_manager's update_rate is an integer parameter [Hz]; refuse a fractional one."""
    rate = spec.control.controller_update_rate
    if not float(rate).is_integer():
        raise InputError(
            f"{rate:g} Hz: controller_manager needs a whole number of Hz",
            file=source,
            field="control.controller_update_rate",
        )
    return int(rate)


def ros2_controllers(spec: RobotSpec, source: str | None = None) -> dict[str, Any]:
    """controller_manager + joint_state_broadcaster + a JointTrajectoryController for the arm.

    The mock hardware of the MoveIt demo takes position commands; the spec's
    PD gains are written as the controller's `gains` so that switching the
    command interface to effort (e.g. gazebo_ros2_control) uses them as-is.
    """
    joints = chain_joints(spec)
    gains = {
        j: {"p": float(g.kp), "i": float(g.ki), "d": float(g.kd)}
        for j in joints
        if (g := spec.control.gains.get(j)) is not None
    }
    arm: dict[str, Any] = {
        "joints": joints,
        "command_interfaces": [trajectory_interface(spec, joints, HUMBLE, source)],
        "state_interfaces": ["position", "velocity"],
        "allow_nonzero_velocity_at_trajectory_end": True,
    }
    if gains:
        arm["gains"] = gains
    return {
        "controller_manager": {
            "ros__parameters": {
                "update_rate": controller_update_rate(spec, source),
                ARM_CONTROLLER: {"type": "joint_trajectory_controller/JointTrajectoryController"},
                JOINT_STATE_BROADCASTER: {"type": "joint_state_broadcaster/JointStateBroadcaster"},
            }
        },
        ARM_CONTROLLER: {"ros__parameters": arm},
    }


def moveit_controllers(spec: RobotSpec) -> dict[str, Any]:
    """How MoveIt's simple controller manager reaches the arm controller's action server."""
    return {
        "moveit_controller_manager": (
            "moveit_simple_controller_manager/MoveItSimpleControllerManager"
        ),
        "moveit_simple_controller_manager": {
            "controller_names": [ARM_CONTROLLER],
            ARM_CONTROLLER: {
                "type": "FollowJointTrajectory",
                "action_ns": "follow_joint_trajectory",
                "default": True,
                "joints": chain_joints(spec),
            },
        },
    }


def passive_joints(spec: RobotSpec) -> list[str]:
    """Movable joints outside the planning chain (the wheels): state only, never commanded.

    They still go to ros2_control so that joint_state_broadcaster publishes them;
    otherwise robot_state_publisher has no TF for the wheels and MoveIt waits for
    "the complete state of the robot".
    """
    chain = set(chain_joints(spec))
    return [n for n, j in spec.all_joints().items() if j.type != "fixed" and n not in chain]


def initial_positions(spec: RobotSpec) -> dict[str, Any]:
    """Start of the mock hardware: the `home` pose if the spec has one, clamped into the limits.

    A joint it leaves out rests (`robot.joints.rest`: 0, else the middle of its range).
    """
    values = spec.pose("home") if "home" in spec.poses else {}
    joints = spec.all_joints()
    out = {}
    for name in [*chain_joints(spec), *passive_joints(spec)]:
        bounds = position_bounds(joints[name].type, joints[name].limit)
        v = values.get(name, rest(*bounds) if bounds is not None else 0.0)
        if bounds is not None:
            v = min(max(v, bounds[0]), bounds[1])
        out[name] = float(v)
    return {"initial_positions": out}


def pilz_cartesian_limits() -> dict[str, Any]:
    """Setup Assistant defaults; MoveItConfigsBuilder loads this file unconditionally."""
    return {
        "cartesian_limits": {
            "max_trans_vel": 1.0,
            "max_trans_acc": 2.25,
            "max_trans_dec": -5.0,
            "max_rot_vel": 1.57,
        }
    }


def setup_assistant(urdf_package: str, urdf_path: str, srdf_path: str) -> dict[str, Any]:
    """`.setup_assistant`: lets MoveItConfigsBuilder and the Setup Assistant find URDF and SRDF.

    The URDF named is the MoveIt package's own `config/<name>.urdf.xacro` (the
    description plus ros2_control), which every MoveItConfigsBuilder version loads.
    """
    return {
        "moveit_setup_assistant_config": {
            "URDF": {"package": urdf_package, "relative_path": urdf_path},
            "SRDF": {"relative_path": srdf_path},
            "CONFIG": {"author_name": "armcli", "generated_timestamp": 0},
        }
    }
