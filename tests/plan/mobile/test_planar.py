"""The planar-reach arm's closed form against Pinocchio and a brute-force joint grid.

`planar_arm` is read off the model; its forward kinematics must be Pinocchio's (the
course robot's tool point at random joint values), its inverse kinematics must land on
the point, and its nearest reachable point must be no farther than the nearest point of
a 0.1-degree grid of both joints (the grid's own spacing the only slack).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from armcli.plan.mobile.virtual import load_mobile
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC, FIXTURES

FK_TOL = 1e-12  # [m] two evaluations of the same kinematics
IK_TOL = 1e-9  # [m]
GRID_SLACK = 1e-12  # [m] the closed form is never farther than the grid's nearest point


def test_the_course_arm_is_planar_and_matches_pinocchio() -> None:
    mobile = load_mobile(read_robot(DEFAULT_SPEC))
    arm = mobile.planar
    assert arm is not None and arm.joints == mobile.arm
    robot = mobile.arm_robot()
    data = robot.model.createData()
    rng = np.random.default_rng(0)
    for q in rng.uniform(arm.lower, arm.upper, (200, 2)):
        pin.forwardKinematics(robot.model, data, robot.q(q))
        tool = pin.updateFramePlacement(robot.model, data, robot.tool_frame).act(robot.tool_offset)
        assert np.linalg.norm(arm.point(q) - tool) < FK_TOL
        u, w, lateral = arm.coordinates(tool)
        assert abs(lateral) < FK_TOL
        solutions = arm.ik(u, w)
        assert solutions, q
        assert all(np.linalg.norm(arm.plane(s) - (u, w)) < IK_TOL for s in solutions)


def test_nearest_is_no_farther_than_a_brute_force_grid() -> None:
    arm = load_mobile(read_robot(DEFAULT_SPEC)).planar
    assert arm is not None
    g = np.linspace(0.0, math.pi / 2, 901)
    grid = np.array([arm.plane((a, b)) for a in g[::6] for b in g[::6]])
    rng = np.random.default_rng(1)
    points = np.column_stack([rng.uniform(-1.0, 0.5, 300), rng.uniform(-0.6, 0.9, 300)])
    q, miss = arm.nearest_batch(points[:, 0], points[:, 1])
    for i, p in enumerate(points):
        best = float(np.min(np.linalg.norm(grid - p, axis=1)))
        mine = float(np.min(miss[i]))
        assert mine <= best + GRID_SLACK, (p, mine, best)
        k = int(np.argmin(miss[i]))
        assert abs(np.linalg.norm(arm.plane(q[i, k]) - p) - mine) < IK_TOL


def test_the_height_range_is_the_grids_extremes() -> None:
    arm = load_mobile(read_robot(DEFAULT_SPEC)).planar
    assert arm is not None
    lo, hi = arm.height_range()
    # the course arm: links 0.3 and 0.3 from the shoulder, 0..pi/2 each (specs/my_robot.yaml):
    # straight up (0.6) at the top, the hand hanging down from a level forearm (-0.3) below
    assert abs(hi - 0.6) < IK_TOL and abs(lo + 0.3) < IK_TOL


def test_an_arm_with_a_waist_is_not_planar() -> None:
    mobile = load_mobile(read_robot(FIXTURES / "plan" / "mobile" / "rover_arm.urdf"))
    assert mobile.planar is None
    assert mobile.arm == ("joint1", "joint2", "joint3", "joint4")


def test_the_closed_form_keeps_its_values_when_the_robot_computes_again() -> None:
    """`planar_arm` reads the robot's shared Data: its vectors must be copies, not views
    that the next computation in that Data moves (the placement's plot did, and shaded
    the wrong base positions)."""
    mobile = load_mobile(read_robot(DEFAULT_SPEC))
    arm = mobile.planar
    assert arm is not None
    before = {k: np.copy(getattr(arm, k)) for k in ("shoulder", "axis", "e_u", "l1", "l2")}
    robot = mobile.robot
    robot.robot.frame_pose("hand_link", robot.q(mobile.x((1.0, 2.0, 0.5), (0.7, 0.9))))
    for k, v in before.items():
        np.testing.assert_array_equal(getattr(arm, k), v, err_msg=k)
