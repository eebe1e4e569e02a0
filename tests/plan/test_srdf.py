"""SRDF planning groups (plan.srdf): joints, links, chains and subgroups, as MoveIt reads them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from armcli.errors import InputError
from armcli.io.packages import PackageLookup
from armcli.plan.inputs import load_context
from armcli.plan.srdf import read_srdf
from armcli.urdf.source import read_robot
from tests.helpers import run_main

INERTIAL = (
    '<inertial><mass value="0.5"/><inertia ixx="0.002" iyy="0.002" izz="0.002" '
    'ixy="0" ixz="0" iyz="0"/></inertial>'
)
BOX = '<collision><geometry><box size="0.04 0.04 0.04"/></geometry></collision>'
# base -j1-> upper -j2-> fore -flange_joint(fixed)-> flange -finger(prismatic)-> finger_a,
# -finger_b (mimic of finger)-> finger_b: an arm with a two-finger gripper
URDF = f"""<robot name="gripper_arm">
  <link name="base">{INERTIAL}{BOX}</link>
  <link name="upper">{INERTIAL}</link>
  <link name="fore">{INERTIAL}</link>
  <link name="flange">{INERTIAL}</link>
  <link name="finger_a">{INERTIAL}</link>
  <link name="finger_b">{INERTIAL}</link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="flange_joint" type="fixed"><parent link="fore"/><child link="flange"/>
    <origin xyz="0 0 0.3"/></joint>
  <joint name="finger" type="prismatic"><parent link="flange"/><child link="finger_a"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.04" effort="5" velocity="0.1"/></joint>
  <joint name="finger_b_joint" type="prismatic"><parent link="flange"/>
    <child link="finger_b"/><axis xyz="-1 0 0"/>
    <limit lower="0" upper="0.04" effort="5" velocity="0.1"/>
    <mimic joint="finger"/></joint>
</robot>
"""
SRDF = """<robot name="gripper_arm">
  <group name="arm"><chain base_link="base" tip_link="flange"/></group>
  <group name="hand"><link name="finger_a"/><link name="finger_b"/></group>
  <group name="by_joint"><joint name="j2"/><joint name="j1"/></group>
  <group name="all"><group name="arm"/><group name="hand"/></group>
  <group name="upside_down"><chain base_link="flange" tip_link="base"/></group>
  <group name="stranger"><joint name="nope"/></group>
  <group_state name="up" group="arm"><joint name="j1" value="0"/><joint name="j2" value="0"/>
  </group_state>
  <group_state name="bent" group="arm"><joint name="j1" value="1"/>
    <joint name="j2" value="0.5"/></group_state>
</robot>
"""


@pytest.fixture
def files(tmp_path: Path) -> tuple[Path, Path]:
    urdf, srdf = tmp_path / "arm.urdf", tmp_path / "arm.srdf"
    urdf.write_text(URDF)
    srdf.write_text(SRDF)
    return urdf, srdf


def test_groups_resolve_like_moveit(files: tuple[Path, Path]) -> None:
    urdf_path, srdf_path = files
    srdf, urdf = read_srdf(srdf_path), read_robot(urdf_path).robot
    assert list(srdf.groups) == ["arm", "hand", "by_joint", "all", "upside_down", "stranger"]
    # a chain is every joint from base to tip, the fixed one included (MoveIt's group)
    assert srdf.group_joints("arm", urdf) == ("j1", "j2", "flange_joint")
    assert srdf.group_joints("hand", urdf) == ("finger", "finger_b_joint")  # joint above a link
    assert srdf.group_joints("by_joint", urdf) == ("j1", "j2")  # document order
    assert srdf.group_joints("all", urdf) == ("j1", "j2", "flange_joint", "finger",
                                              "finger_b_joint")  # fmt: skip
    for group, words in (("upside_down", "not below base"), ("stranger", "'nope' is not in"),
                         ("missing", "valid: arm, hand")):  # fmt: skip
        with pytest.raises(InputError, match=words):
            srdf.group_joints(group, urdf)


def test_a_group_plans_its_movable_joints_only(files: tuple[Path, Path]) -> None:
    urdf_path, srdf_path = files
    robot_file = read_robot(urdf_path)
    arm = load_context(robot_file, srdf=srdf_path, group="arm", search=PackageLookup())
    assert arm.context.robot.joints == ("j1", "j2")  # the fixed flange joint left out
    hand = load_context(robot_file, srdf=srdf_path, group="hand", search=PackageLookup())
    assert hand.context.robot.joints == ("finger",)  # the mimic finger follows it
    every = load_context(robot_file, srdf=srdf_path, search=PackageLookup())
    assert every.context.robot.joints == ("j1", "j2", "finger")  # no group: every movable one
    with pytest.raises(InputError, match="not both"):
        load_context(robot_file, srdf=srdf_path, group="arm", joints=["j1"])
    with pytest.raises(InputError, match="from an SRDF"):
        load_context(robot_file, group="arm")


def test_plan_group_on_the_command_line(
    files: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    urdf_path, srdf_path = files
    out = tmp_path / "t.yaml"
    args = ["plan", "--urdf", urdf_path, "--srdf", srdf_path, "--group", "arm"]
    code, stdout, err = run_main([*args, "--from", "up", "--to", "bent", "-o", out], capsys)
    assert code == 0, err
    assert "joints: j1, j2" in stdout and 'joint_names: ["j1", "j2"]' in out.read_text()
    code, _, err = run_main([*args[:-1], "nope", "--to", "bent"], capsys)
    assert code == 2 and err.startswith("error: --group: unknown planning group 'nope'"), err
    doc = yaml.safe_load(out.read_text())
    last = doc["points"][-1]["positions"]
    np.testing.assert_allclose(last, [1.0, 0.5], atol=1e-9)  # `bent`, in the group's order


def test_the_viewer_panel_plans_a_group_too(files: tuple[Path, Path], tmp_path: Path) -> None:
    from armcli.view.planning import load_session

    urdf_path, srdf_path = files
    session = load_session(read_robot(urdf_path), srdf=srdf_path, group="arm", save_dir=tmp_path)
    assert session.context.robot.joints == ("j1", "j2")
