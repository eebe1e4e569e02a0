"""Loading a planning context from robot files (plan.inputs)."""

from __future__ import annotations

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
    assert loaded.context.checker.free(robot.q(x))
