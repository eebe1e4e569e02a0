"""The spec's ros2_control interfaces reach both ROS targets and the built URDF."""

from __future__ import annotations

import pytest
import yaml
from lxml import etree

from armcli.compiler.expand import expand_urdfs
from armcli.errors import SpecError
from armcli.ros import jazzy
from armcli.ros import moveit as mc
from armcli.ros.ros2_control import ros2_control_xacro
from armcli.spec.load import load_spec, loads_spec
from tests.helpers import DEFAULT_SPEC

CONTROL = """
ros2_control:
  name: course_arm
  hardware:
    plugin: my_driver/ArmSystem
    params: {port: /dev/ttyUSB0}
  joints:
    arm_base_forearm_joint:
      command_interfaces: {position: {min: 0, max: pi/2}}
      state_interfaces: {position: {initial_value: 0.1}, velocity: {}}
    forearm_hand_joint:
      command_interfaces: {position: {min: 0, max: pi/2}, velocity: {max: 2}}
      state_interfaces: {position: {}, velocity: {}}
"""


@pytest.fixture
def spec():
    return loads_spec(DEFAULT_SPEC.read_text() + CONTROL, "specs/my_robot.yaml")


def _joints(xml: bytes) -> dict[str, etree._Element]:
    root = etree.fromstring(xml)
    return {
        str(j.get("name")): j for j in root.iter("joint") if j.getparent().tag == "ros2_control"
    }


def test_humble_moveit_block_takes_the_spec_interfaces(spec) -> None:
    joints = _joints(ros2_control_xacro(spec))
    fore = joints["arm_base_forearm_joint"]
    cmd = fore.find("command_interface")
    assert cmd is not None and cmd.get("name") == "position"
    assert [(p.get("name"), p.text) for p in cmd] == [("min", "0"), ("max", "1.5707963267948966")]
    # MoveIt's initial_positions.yaml still sets the start
    start = fore.find("state_interface/param")
    assert start is not None and start.text == "${initial_positions['arm_base_forearm_joint']}"
    hand = [c.get("name") for c in joints["forearm_hand_joint"].findall("command_interface")]
    assert hand == ["position", "velocity"]
    assert set(joints) >= {"base_left_wheel_joint"}  # wheels: state only, defaults
    assert joints["base_left_wheel_joint"].find("command_interface") is None


def test_controllers_use_the_common_interface_and_need_no_gains_for_position(spec) -> None:
    arm = mc.ros2_controllers(spec)[mc.ARM_CONTROLLER]["ros__parameters"]
    assert arm["command_interfaces"] == ["position"]
    gz = jazzy.controllers(spec)[mc.ARM_CONTROLLER]["ros__parameters"]
    assert gz["command_interfaces"] == ["position"] and "gains" not in gz
    top = etree.fromstring(jazzy.top_xacro(spec, "my_robot_bringup", whole=True, header="x"))
    cmd = top.find(".//ros2_control/joint[@name='arm_base_forearm_joint']/command_interface")
    assert cmd is not None and cmd.get("name") == "position"


def test_default_jazzy_is_effort_with_gains(default_spec_path) -> None:
    spec = load_spec(default_spec_path)
    gz = jazzy.controllers(spec)[mc.ARM_CONTROLLER]["ros__parameters"]
    assert gz["command_interfaces"] == ["effort"] and set(gz["gains"]) == set(spec.control.gains)


def test_build_writes_the_block_when_hardware_is_given(spec) -> None:
    urdf = etree.fromstring(expand_urdfs(spec)["my_robot.urdf"])
    (block,) = urdf.findall("ros2_control")
    assert (block.get("name"), block.get("type")) == ("course_arm", "system")
    assert block.findtext("hardware/plugin") == "my_driver/ArmSystem"
    assert block.find("hardware/param[@name='port']").text == "/dev/ttyUSB0"
    init = block.find("joint[@name='arm_base_forearm_joint']/state_interface/param")
    assert init is not None and (init.get("name"), init.text) == ("initial_value", "0.1")


def test_no_common_interface_is_refused(spec) -> None:
    text = DEFAULT_SPEC.read_text() + CONTROL.replace(
        "{position: {min: 0, max: pi/2}, velocity: {max: 2}}", "{velocity: {max: 2}}"
    )
    odd = loads_spec(text)
    with pytest.raises(Exception, match="share no command interface"):
        mc.ros2_controllers(odd)


def test_unknown_or_fixed_joints_are_refused() -> None:
    bad = DEFAULT_SPEC.read_text() + CONTROL.replace("forearm_hand_joint:", "caster_wheel_joint:")
    with pytest.raises(SpecError, match=r"ros2_control\.joints\.caster_wheel_joint: a fixed joint"):
        loads_spec(bad)


def test_yaml_of_the_controllers_is_plain(spec) -> None:
    text = mc.dump_yaml(jazzy.controllers(spec)).decode()
    assert yaml.safe_load(text)[mc.ARM_CONTROLLER]["ros__parameters"]["joints"] == [
        "arm_base_forearm_joint",
        "forearm_hand_joint",
    ]


def _mjcf_actuators(text: str) -> tuple[dict[str, etree._Element], list[str]]:
    from armcli.export.mjcf import build_mjcf
    from armcli.urdf.read import parse_urdf

    spec = loads_spec(text, "specs/my_robot.yaml")
    urdf = parse_urdf(expand_urdfs(spec)["standalone_arm.urdf"], "standalone_arm.urdf")
    out = build_mjcf(urdf, spec)
    root = etree.fromstring(out.model)
    acts = {str(a.get("joint")): a for a in root.find("actuator")}
    mujoco = pytest.importorskip("mujoco")
    mujoco.MjModel.from_xml_string(out.model.decode())  # MuJoCo accepts what it is given
    return acts, [f"{n.what}: {n.done}" for n in out.notes]


def test_mjcf_export_follows_the_ros2_control_interfaces() -> None:
    """mujoco_ros2_control's mapping: the PD loop with the effort interface's force range,
    a velocity-only joint as a velocity actuator with the interface's range."""
    control = """
ros2_control:
  joints:
    arm_base_forearm_joint:
      command_interfaces: {effort: {min: -30, max: 30}}
      state_interfaces: {position: {}, velocity: {}}
    forearm_hand_joint:
      command_interfaces: {velocity: {min: -2, max: 2}}
      state_interfaces: {position: {}, velocity: {}}
"""
    acts, _ = _mjcf_actuators(DEFAULT_SPEC.read_text() + control)
    shoulder, hand = acts["arm_base_forearm_joint"], acts["forearm_hand_joint"]
    assert shoulder.tag == "position" and shoulder.get("forcerange") == "-30 30"
    assert (hand.tag, hand.get("ctrlrange")) == ("velocity", "-2 2")
    assert hand.get("kv") == "1.5"  # the spec's Kd
    default, _ = _mjcf_actuators(DEFAULT_SPEC.read_text())
    assert default["arm_base_forearm_joint"].get("forcerange") == "-100 100"  # effort limit


def test_mjcf_export_leaves_read_only_joints_unactuated() -> None:
    control = """
ros2_control:
  joints:
    arm_base_forearm_joint:
      command_interfaces: {position: {}}
      state_interfaces: {position: {}}
    forearm_hand_joint:
      state_interfaces: {position: {}}
"""
    acts, notes = _mjcf_actuators(DEFAULT_SPEC.read_text() + control)
    assert set(acts) == {"arm_base_forearm_joint"}
    assert any("ros2_control only reads forearm_hand_joint" in n for n in notes)
