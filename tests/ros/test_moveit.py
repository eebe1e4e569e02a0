"""MoveIt / ros2_control YAML: the keys ROS 2 reads, with values traced to the spec and URDF."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from lxml import etree

from armcli.defaults import DEFAULT_JOINT_ACCELERATION
from armcli.errors import InputError
from armcli.ros import moveit as mc
from armcli.spec.load import load_spec, loads_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.read import parse_urdf


@pytest.fixture(scope="module")
def spec(default_spec_path: Path) -> RobotSpec:
    return load_spec(default_spec_path)


@pytest.fixture(scope="module")
def urdf_root(built_dir: Path) -> etree._Element:
    return etree.parse(str(built_dir / "my_robot.urdf")).getroot()


def _roundtrip(data: dict) -> dict:
    """What a ROS 2 YAML reader sees: the emitted bytes parsed back."""
    return yaml.safe_load(mc.dump_yaml(data, header="generated\nby a test"))


def _urdf_joints(root: etree._Element) -> dict[str, etree._Element]:
    return {j.get("name", ""): j for j in root.findall("joint")}


def test_kinematics_is_kdl_position_only_for_the_arm_group(spec: RobotSpec) -> None:
    k = _roundtrip(mc.kinematics(spec))
    assert list(k) == ["arm"]  # the SRDF planning group
    assert k["arm"]["kinematics_solver"] == "kdl_kinematics_plugin/KDLKinematicsPlugin"
    assert k["arm"]["position_only_ik"] is True
    assert k["arm"]["kinematics_solver_timeout"] > 0


def test_joint_limits_come_from_the_urdf(spec: RobotSpec, built_dir: Path) -> None:
    data = (built_dir / "my_robot.urdf").read_bytes()
    urdf = parse_urdf(data, "my_robot.urdf")
    joints = ["arm_base_forearm_joint", "forearm_hand_joint"]
    limits = _roundtrip(mc.joint_limits(urdf, joints))["joint_limits"]
    assert list(limits) == joints
    root = etree.fromstring(data)
    for name in joints:
        (lim,) = root.findall(f"joint[@name='{name}']/limit")
        assert limits[name]["has_velocity_limits"] is True
        assert limits[name]["max_velocity"] == float(lim.get("velocity", "nan"))
        assert limits[name]["max_effort"] == float(lim.get("effort", "nan"))
        assert isinstance(limits[name]["max_acceleration"], float)  # MoveIt reads a double
        # the course spec gives no acceleration: the default `plan` uses for it too
        assert limits[name]["has_acceleration_limits"] is True
        assert limits[name]["max_acceleration"] == DEFAULT_JOINT_ACCELERATION


def test_joint_limits_take_the_urdf_acceleration() -> None:
    text = (
        b'<robot name="r"><link name="a"/><link name="b"/>'
        b'<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        b'<limit lower="-1" upper="1" effort="5" velocity="2" acceleration="7.5"/></joint>'
        b"</robot>"
    )
    limits = mc.joint_limits(parse_urdf(text, "r.urdf"), ["j"])["joint_limits"]
    assert limits["j"]["max_acceleration"] == 7.5  # URDF 1.2's attribute, as written


def test_ros2_controllers(spec: RobotSpec, urdf_root: etree._Element) -> None:
    c = _roundtrip(mc.ros2_controllers(spec))
    cm = c["controller_manager"]["ros__parameters"]
    # specs/my_robot.yaml: control.controller_update_rate: 1000; an int, as controller_manager wants
    assert cm["update_rate"] == 1000 and isinstance(cm["update_rate"], int)
    assert cm["joint_state_broadcaster"]["type"] == "joint_state_broadcaster/JointStateBroadcaster"
    assert cm["arm_controller"]["type"] == "joint_trajectory_controller/JointTrajectoryController"
    arm = c["arm_controller"]["ros__parameters"]
    urdf_joints = _urdf_joints(urdf_root)
    assert arm["joints"] == ["arm_base_forearm_joint", "forearm_hand_joint"]
    for j in arm["joints"]:
        assert urdf_joints[j].get("type") == "revolute"
        gains = spec.control.gains[j]
        assert arm["gains"][j] == {"p": gains.kp, "i": gains.ki, "d": gains.kd}
    assert set(arm["command_interfaces"]) <= {"position", "velocity", "effort"}
    assert "position" in arm["state_interfaces"]


def test_fractional_update_rate_is_refused(default_spec_path: Path) -> None:
    text = default_spec_path.read_text().replace(
        "controller_update_rate: 1000", "controller_update_rate: 1000.5"
    )
    spec = loads_spec(text, "edited.yaml")
    with pytest.raises(InputError) as err:
        mc.ros2_controllers(spec, "edited.yaml")
    assert err.value.field == "control.controller_update_rate"
    assert "edited.yaml" in str(err.value)


def test_moveit_controllers_point_at_the_ros2_controller(spec: RobotSpec) -> None:
    m = _roundtrip(mc.moveit_controllers(spec))
    assert m["moveit_controller_manager"].endswith("MoveItSimpleControllerManager")
    scm = m["moveit_simple_controller_manager"]
    ros2 = mc.ros2_controllers(spec)
    for name in scm["controller_names"]:
        assert name in ros2["controller_manager"]["ros__parameters"]
        assert scm[name]["type"] == "FollowJointTrajectory"
        assert scm[name]["action_ns"] == "follow_joint_trajectory"
        assert scm[name]["joints"] == ros2[name]["ros__parameters"]["joints"]


def test_initial_positions_are_home_and_within_limits(
    spec: RobotSpec, urdf_root: etree._Element
) -> None:
    init = _roundtrip(mc.initial_positions(spec))["initial_positions"]
    # every joint that moves in the URDF gets a start value, so the mock hardware publishes it
    movable = {n for n, j in _urdf_joints(urdf_root).items() if j.get("type") != "fixed"}
    assert set(init) == movable
    home = spec.pose("home")  # specs/my_robot.yaml: home is all zeros
    assert {j: init[j] for j in home} == home
    assert mc.passive_joints(spec) == ["base_right_wheel_joint", "base_left_wheel_joint"]
    for j in mc.passive_joints(spec):
        assert init[j] == 0.0  # continuous wheels: no limits, start at 0
    for j in home:
        lim = spec.arm.joints[j].limit
        assert lim is not None and lim.lower <= init[j] <= lim.upper


def test_setup_assistant_and_pilz_files_have_the_keys_moveit_reads() -> None:
    sa = _roundtrip(mc.setup_assistant("pkg", "config/r.urdf.xacro", "config/r.srdf"))
    cfg = sa["moveit_setup_assistant_config"]
    assert cfg["URDF"] == {"package": "pkg", "relative_path": "config/r.urdf.xacro"}
    assert cfg["SRDF"]["relative_path"] == "config/r.srdf"
    limits = _roundtrip(mc.pilz_cartesian_limits())["cartesian_limits"]
    assert set(limits) == {"max_trans_vel", "max_trans_acc", "max_trans_dec", "max_rot_vel"}


def test_dump_yaml_is_deterministic_and_keeps_order() -> None:
    data = {"b": 1, "a": [1.5, 2], "c": {"z": True, "y": "x"}}
    text = mc.dump_yaml(data, header="h")
    assert text == mc.dump_yaml(data, header="h")
    assert text.startswith(b"# h\n")
    assert list(yaml.safe_load(text)) == ["b", "a", "c"]
