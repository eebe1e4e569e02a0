"""Loading a planning context from robot files (plan.inputs)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from armcli.io.packages import PackageLookup
from armcli.plan.inputs import load_context
from armcli.urdf.source import read_robot
from tests.helpers import FIXTURES

MESHED = FIXTURES / "meshed" / "mesh_arm_clone"


def test_a_urdf_with_package_meshes_and_no_srdf_loads() -> None:
    # the allowed-collision matrix (computed here, no --srdf) must resolve package:// meshes
    # through the same lookup as the planner's own geometry; it used Pinocchio's and failed
    search = PackageLookup({"mesh_arm_description": MESHED})
    loaded = load_context(read_robot(MESHED / "urdf" / "mesh_arm.urdf"), search=search)
    robot = loaded.context.robot
    assert "joint1" in robot.joints
    x = np.zeros(len(robot.joints))
    assert loaded.context.checker.free(x)


VISUAL_ELSEWHERE = """<robot name="two">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="arm"><inertial><origin xyz="0 0 0.2"/><mass value="0.5"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="package://absent_description/meshes/arm.dae"/>
    </geometry></visual>
    <collision><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.03" length="0.3"/>
    </geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""


def test_a_visual_mesh_of_an_absent_package_does_not_stop_planning(tmp_path: Path) -> None:
    # only collision geometry is loaded for planning: a robot whose visual meshes live in a
    # package not installed here (common for real descriptions) still plans
    path = tmp_path / "two.urdf"
    path.write_text(VISUAL_ELSEWHERE)
    loaded = load_context(read_robot(path), search=PackageLookup())
    robot = loaded.context.robot
    assert robot.joints == ("j1",)
    assert loaded.context.checker.free(np.zeros(1))
