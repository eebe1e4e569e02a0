"""One tool point for every command: the rule itself, and check / simulate / view agreeing."""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.robot.tool import ToolPoint, spec_tool, tool_point
from armcli.ros.srdf import arm_chain
from armcli.sim import job as simjob
from armcli.sim.options import SimOptions
from armcli.spec.load import load_spec
from armcli.urdf.read import parse_urdf, read_urdf
from armcli.urdf.source import RobotFile, read_robot
from armcli.view.scene import load_robot
from tests.helpers import DEFAULT_SPEC

_INERTIAL = (
    '<inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" '
    'ixy="0" ixz="0" iyz="0"/></inertial>'
)


def _link(name: str) -> str:
    return f'<link name="{name}">{_INERTIAL}</link>'


def _joint(name: str, kind: str, parent: str, child: str) -> str:
    limit = '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind != "fixed" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>{limit}</joint>'
    )


# base -> j1 -> l1 -> j2 -> l2 -> (fixed) tip; l1 -> (fixed) camera. l2 and tip both sit
# below two movable joints; l2 comes first in the file, so it is the tool link.
ARM = (
    '<robot name="probe">'
    + "".join(_link(n) for n in ("base", "l1", "l2", "tip", "camera"))
    + _joint("j1", "revolute", "base", "l1")
    + _joint("j2", "revolute", "l1", "l2")
    + _joint("tip_fixed", "fixed", "l2", "tip")
    + _joint("camera_fixed", "fixed", "l1", "camera")
    + "</robot>"
)


@pytest.fixture
def arm_file(tmp_path: Path) -> Path:
    path = tmp_path / "probe.urdf"
    path.write_text(ARM)
    return path


def test_deepest_link_counts_movable_joints_only() -> None:
    assert tool_point(parse_urdf(ARM.encode(), "probe.urdf")) == ToolPoint("l2")
    # with the tip listed before l2, the tie goes to the tip (file order)
    swapped = ARM.replace(_link("l2") + _link("tip"), _link("tip") + _link("l2"))
    assert tool_point(parse_urdf(swapped.encode(), "probe.urdf")) == ToolPoint("tip")


def test_spec_tool_wins_when_its_link_exists() -> None:
    spec = load_spec(DEFAULT_SPEC)
    assert spec.arm.tool is not None
    robot = read_robot(DEFAULT_SPEC)
    assert tool_point(robot.robot, spec) == ToolPoint(spec.arm.tool.link, spec.arm.tool.xyz)


def test_check_simulate_and_view_report_the_same_point(arm_file: Path) -> None:
    summary = check_urdf(read_urdf(arm_file), CheckOptions()).summary
    assert summary is not None and summary.end_effector == "l2"
    assert load_robot(arm_file).tool == ToolPoint("l2")
    opts = SimOptions(message="joint_names: [j1]\npoints: [{positions: [0.1]}]", kp=(50.0,),
                      kd=(5.0,))  # fmt: skip
    job = simjob.prepare(read_robot(arm_file), opts)
    assert job.tool_label.startswith("l2 ")


def test_label_is_the_link_plus_the_offset_when_there_is_one() -> None:
    assert ToolPoint("hand").label == "hand"
    assert ToolPoint("hand", (0.0, 0.0, 0.1)).label == "hand + (0, 0, 0.1)"


def test_check_and_simulate_print_the_same_label() -> None:
    spec = load_spec(DEFAULT_SPEC)
    assert spec.arm.tool is not None and any(spec.arm.tool.xyz)  # an offset to print
    robot = read_robot(DEFAULT_SPEC)
    summary = check_urdf(robot.robot, CheckOptions(spec=spec)).summary
    message = f"joint_names: [{spec.movable_arm_joints()[0]}]\npoints: [{{positions: [0.1]}}]"
    job = simjob.prepare(RobotFile.of_spec(spec), SimOptions(message=message))
    assert summary is not None and summary.end_effector
    assert job.tool_label.startswith(summary.end_effector + " in ")


def test_a_spec_without_tool_and_moveit_end_at_the_same_link() -> None:
    spec = load_spec(DEFAULT_SPEC)
    bare = spec.model_copy(update={"arm": spec.arm.model_copy(update={"tool": None})})
    robot = read_robot(DEFAULT_SPEC)
    tip = spec_tool(bare).link
    assert tip == arm_chain(bare)[1]  # the SRDF's planning chain asks the same rule
    assert tool_point(robot.robot, bare) == ToolPoint(tip)
    # the deepest arm link of my_robot.yaml: arm_base_link -> forearm_link -> hand_link
    assert tip == "hand_link"


def test_a_gripper_finger_is_never_the_tool() -> None:
    """OpenManipulator-X's shape (issue 31): link5 carries two prismatic fingers (the right
    one a mimic) and a fixed end_effector_link; the fingers were the tool point, 5 joints
    deep, and the reach swept the gripper's stroke."""
    links = ["world", "link1", "link2", "link5", "gripper_left_link", "gripper_right_link",
             "end_effector_link"]  # fmt: skip
    right = _joint("gripper_right_joint", "prismatic", "link5", "gripper_right_link")
    right = right.replace("</joint>", '<mimic joint="gripper_left_joint"/></joint>')
    urdf = parse_urdf(
        (
            '<robot name="omx">'
            + "".join(_link(n) for n in links)
            + _joint("joint1", "revolute", "world", "link1")
            + _joint("joint2", "revolute", "link1", "link2")
            + _joint("joint4", "revolute", "link2", "link5")
            + _joint("gripper_left_joint", "prismatic", "link5", "gripper_left_link")
            + right
            + _joint("end_effector_joint", "fixed", "link5", "end_effector_link")
            + "</robot>"
        ).encode(),
        "omx.urdf",
    )
    # link5 and end_effector_link are both 3 movable joints deep; the second is named a tool
    assert tool_point(urdf) == ToolPoint("end_effector_link")
    summary = check_urdf(urdf, CheckOptions()).summary
    assert summary is not None and summary.reach is not None
    assert "gripper_left_joint" not in summary.reach.joints  # the reach is the arm's
