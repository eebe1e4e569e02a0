"""armcli.robot.collision: the one pair set-up, against boxes whose overlap is known by hand."""

from __future__ import annotations

import numpy as np
import pytest

from armcli.robot.collision import SelfCollision, add_pairs, box_corners, geometry_links, placements
from armcli.robot.model import Robot
from armcli.urdf.read import parse_urdf

# A 0.2 m cube on the base; a slider carrying two 0.1 m cubes (one object each) along x;
# a fixed tip 0.3 m further along with its own 0.1 m cube. The slider's cubes reach the
# base cube while x < (0.2 + 0.1) / 2 = 0.15 m: contact is decided by the hand's arithmetic.
URDF = b"""<robot name="boxes">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="slider">
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    <collision><origin xyz="0 0 0.3"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    <inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>
    </inertial></link>
  <link name="tip"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="x" type="prismatic"><parent link="base"/><child link="slider"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>
  <joint name="tip_joint" type="fixed"><parent link="slider"/><child link="tip"/>
    <origin xyz="0.3 0 0"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.load(parse_urdf(URDF, "boxes.urdf"))


def test_pairs_join_objects_of_different_links_the_rule_keeps(robot: Robot) -> None:
    gmodel = robot.collision_model()
    owners = geometry_links(robot.model, gmodel)
    assert owners == ["base", "slider", "slider", "tip"]  # the URDF's <collision> elements
    pairs = add_pairs(gmodel, owners, lambda i, j: "tip" not in (owners[i], owners[j]))
    assert pairs == [(0, 1), (0, 2)]  # never the slider's two objects with each other
    assert [(p.first, p.second) for p in gmodel.collisionPairs] == pairs


def test_self_collision_finds_the_overlap_where_the_hand_says(robot: Robot) -> None:
    check = SelfCollision(robot, lambda a, b: True)
    slider_base, slider_tip = ("base", "slider"), ("slider", "tip")
    assert check.pairs == [slider_base, slider_base, ("base", "tip"), slider_tip, slider_tip]
    assert check.colliding(robot.q({"x": 0.1})) == [0]  # cubes 0.05 m into each other
    assert check.colliding(robot.q({"x": 0.2})) == []  # 0.05 m apart
    assert check.colliding(robot.q({"x": 0.1}), active=[1, 2]) == []  # the base pair skipped
    # the tip's cube is 0.25 m from the slider's (0.1 m each: apart) and 0.3 m up is clear
    never = SelfCollision(robot, lambda a, b: "base" not in (a, b))
    assert never.colliding(robot.q({"x": 0.0})) == []


def test_placements_and_box_corners_are_where_the_urdf_puts_them(robot: Robot) -> None:
    """At x = 0.2: the base cube at the origin, the slider's at x and 0.3 above it, the
    tip's 0.3 further along x; none turned, so the corners are the centres +- half sizes."""
    gmodel = robot.collision_model()
    q = robot.q({"x": 0.2})
    T = placements(robot, gmodel, q)
    centres = [(0.0, 0.0, 0.0), (0.2, 0.0, 0.0), (0.2, 0.0, 0.3), (0.5, 0.0, 0.0)]
    np.testing.assert_allclose(T[:, :3, 3], centres, atol=1e-12)
    np.testing.assert_allclose(T[:, :3, :3], np.broadcast_to(np.eye(3), (4, 3, 3)), atol=1e-12)
    boxes = box_corners(robot, gmodel, q)
    assert [link for link, _ in boxes] == ["base", "slider", "slider", "tip"]
    for (_, corners), centre, half in zip(boxes, centres, (0.1, 0.05, 0.05, 0.05), strict=True):
        assert corners.shape == (8, 3)
        np.testing.assert_allclose(corners.min(axis=0), np.array(centre) - half, atol=1e-12)
        np.testing.assert_allclose(corners.max(axis=0), np.array(centre) + half, atol=1e-12)
