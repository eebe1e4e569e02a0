"""Placement and `plan --base` on a robot armcli did not write: a rover with a 4-joint arm.

tests/fixtures/plan/mobile/rover_arm.urdf reproduces TurtleBot3 + OpenMANIPULATOR-X's
construction (a waist, then three pitch joints: not a planar-reach arm) and LoCoBot
Kobuki's ROS 1 diff-drive plugin (camelCase tags). The tool point of every placement is
checked with Pinocchio on the fixture's own model (not armcli's virtual base) at the
reported base pose and joints.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from armcli.plan.mobile.place import PlacementError, place
from armcli.plan.mobile.virtual import MobileRobot, load_mobile
from armcli.plan.mobile.wheels import drive_params
from armcli.urdf.source import read_robot
from tests.helpers import FIXTURES, run_cli

ROVER = FIXTURES / "plan" / "mobile" / "rover_arm.urdf"
TOLERANCE = 0.01  # [m] placement's default
TARGETS = [(0.8, 0.3, 0.15), (-0.5, 0.9, 0.25), (1.2, -1.0, 0.08), (0.0, 0.4, 0.3)]


@pytest.fixture(scope="module")
def rover() -> MobileRobot:
    return load_mobile(read_robot(ROVER))


def test_the_ros1_plugin_is_the_drive(rover: MobileRobot) -> None:
    p = drive_params(rover)
    # the fixture's <plugin>: leftJoint, rightJoint, wheelSeparation 0.28, wheelDiameter 0.08,
    # wheelTorque 1.0, wheelAcceleration 0 (no limit), updateRate 30
    assert (p.left_joint, p.right_joint) == ("wheel_left_joint", "wheel_right_joint")
    assert (p.separation, p.radius, p.max_torque, p.max_accel) == (0.28, 0.04, 1.0, 0.0)
    assert p.update_rate == 30.0


@pytest.mark.parametrize("target", TARGETS)
def test_the_placed_tool_reaches_the_target(rover: MobileRobot, target: tuple[float, ...]) -> None:
    try:
        p = place(rover, target, tolerance=TOLERANCE)
    except PlacementError as exc:
        pytest.fail(f"{target}: {exc.reason}")
    assert p.method == "sampled"
    model = pin.buildModelFromUrdf(str(ROVER))  # the fixture itself: a fixed root
    data = model.createData()
    q = pin.neutral(model)
    for name, value in zip(p.joints, p.verdict.q, strict=True):
        q[model.joints[model.getJointId(name)].idx_q] = value
    pin.framesForwardKinematics(model, data, q)
    tool = data.oMf[model.getFrameId("end_effector_link")].translation
    x, y, yaw = p.verdict.base
    world = np.array([x + math.cos(yaw) * tool[0] - math.sin(yaw) * tool[1],
                      y + math.sin(yaw) * tool[0] + math.cos(yaw) * tool[1], tool[2]])  # fmt: skip
    assert np.linalg.norm(world - np.array(target)) <= TOLERANCE
    assert p.verdict.margin is not None and p.verdict.margin > 0.0


def test_plan_base_on_the_rover_writes_its_files(tmp_path: Path) -> None:
    out = tmp_path / "rover"
    res = run_cli(["plan", "--urdf", str(ROVER), "--to-xyz", "1.5,0.3,0.15", "--base",
                   "-o", str(out), "--format", "json"])  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert sorted(p.name for p in out.iterdir()) == ["arm.yaml", "cmd_vel.yaml", "path.yaml"]


def test_a_robot_without_a_drive_gets_one_line(tmp_path: Path) -> None:
    res = run_cli(["plan", "--urdf", str(FIXTURES / "plan" / "two_link.urdf"), "--to-xyz",
                   "0.2,0,0.2", "--base", "-o", str(tmp_path / "x")])  # fmt: skip
    assert res.returncode == 2
    assert "--base: needs a differential drive" in res.stderr
    assert not (tmp_path / "x").exists()
    res = run_cli(["plan", "--urdf", str(FIXTURES / "plan" / "two_link.urdf"), "--to-xyz",
                   "0.2,0,0.2", "--base", "-o", str(tmp_path / "x"), "--execute"])  # fmt: skip
    assert "--base: needs a differential drive" in res.stderr  # the first thing missing


def test_execute_without_a_spec_is_refused_before_planning(tmp_path: Path) -> None:
    res = run_cli(["plan", "--urdf", str(ROVER), "--to-xyz", "1.5,0.3,0.15", "--base",
                   "-o", str(tmp_path / "x"), "--execute"])  # fmt: skip
    assert res.returncode == 2
    assert res.stderr.startswith("error: --execute: drives a spec's robot"), res.stderr
    assert not (tmp_path / "x").exists()


# LoCoBot's wx250s arm ends in a continuous joint (`gripper`): `armcli import` then finds no
# fixed joint whose subtree holds the arm without a continuous joint, and keeps the wheels in
# the spec's arm (no mobile_base): the drive has no base to run.
SPINNER = """  <link name="spinner"/>
  <joint name="gripper" type="continuous">
    <parent link="end_effector_link"/><child link="spinner"/><axis xyz="1 0 0"/>
    <limit effort="1" velocity="3"/>
  </joint>
</robot>"""


def test_execute_without_a_mobile_base_is_refused_before_planning(tmp_path: Path) -> None:
    urdf = tmp_path / "rover_spinner.urdf"
    urdf.write_text(ROVER.read_text().replace("</robot>", SPINNER))
    spec = tmp_path / "rover.yaml"
    res = run_cli(["import", str(urdf), "-o", str(spec)])
    assert res.returncode == 0, res.stderr
    res = run_cli(["plan", str(spec), "--to-xyz", "1.5,0.3,0.15", "--base", "-o",
                   str(tmp_path / "x"), "--execute"])  # fmt: skip
    assert res.returncode == 2
    assert " ".join(res.stderr.split()) == (
        f"error: --execute: drives a spec's mobile_base apart from its arm: {spec} has no "
        "mobile_base (its arm holds the wheels)"
    )
    assert not (tmp_path / "x").exists()
