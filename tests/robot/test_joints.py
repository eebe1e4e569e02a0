"""armcli.robot.joints: the sampling range and the one rest rule for a joint nobody sets."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.robot.joints import rest, span
from armcli.robot.model import Robot
from armcli.urdf.read import parse_urdf
from tests.robot.test_model import URDF


@pytest.mark.parametrize(
    ("lower", "upper", "expected"),
    [
        (-1.0, 2.0, 0.0),  # 0 in range: 0
        (0.0, 0.3, 0.0),  # 0 on a stop is in range
        (0.2, 1.0, 0.6),  # 0 below the range: its middle, (0.2 + 1.0) / 2
        (-2.0, -0.5, -1.25),  # 0 above it: (-2.0 - 0.5) / 2
        (-math.inf, math.inf, 0.0),  # a continuous joint: 0
        (1.0, 0.5, 0.0),  # out of order: sampled over [-pi, pi], where 0 is
    ],
)
def test_rest_is_zero_else_the_middle_of_the_range(
    lower: float, upper: float, expected: float
) -> None:
    # MoveIt's RobotState::setToDefaultValues: 0 if the bounds allow it, else their middle
    assert rest(lower, upper) == expected


def test_span_is_the_range_else_a_turn() -> None:
    assert span(-1.0, 2.0) == (-1.0, 2.0)
    assert span(-math.inf, math.inf) == span(1.0, 0.5) == (-math.pi, math.pi)


def test_robot_rest_follows_its_limits() -> None:
    robot = Robot.load(parse_urdf(URDF, "t.urdf"))
    assert [robot.rest(n) for n in robot.names] == [0.0, 0.0, 0.0, 0.0]
    moved = robot.with_limits(
        lower=np.array([0, 0.2, 0.1, -0.3]), upper=np.array([0, 1, 0.3, -0.1])
    )
    # yaw is continuous (its range stays infinite); the others rest mid-range, 0 being out
    assert [moved.rest(n) for n in moved.names] == pytest.approx([0.0, 0.6, 0.2, -0.2])


OFF_ZERO = b"""<robot name="r"><link name="base"/><link name="a"/><link name="b"/>
  <joint name="lift" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 1 0"/>
    <limit lower="0.2" upper="1.0" effort="5" velocity="1"/></joint>
  <joint name="twist" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 1"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>
</robot>"""


def test_every_consumer_rests_an_unset_joint_by_the_one_rule() -> None:
    """`lift` cannot be at 0 (its range is 0.2..1.0): every reader of an unset joint puts it
    at the middle, 0.6, where the old readers disagreed (0.2, 0.6 or 0)."""
    from armcli.export.mjcf_parts import _poses
    from armcli.robot import sampling
    from armcli.sim.job import start_state
    from armcli.sim.simulate import simulated

    urdf = parse_urdf(OFF_ZERO, "r.urdf")
    robot = Robot.load(urdf)
    middle = (0.2 + 1.0) / 2
    assert robot.q().tolist() == [middle, 0.0]
    assert robot.q({"twist": 0.5}).tolist() == [middle, 0.5]
    assert start_state(simulated(robot), None).tolist() == [middle, 0.0]  # simulate's start
    assert sampling.rest_pose(sampling.bounds(robot.joints)) == [middle, 0.0]  # first sample
    assert _poses(list(urdf.joints), None)["home"] == {"lift": middle, "twist": 0.0}  # MuJoCo
    locked = robot.reduced(["twist"])  # lift locked where it rests: b's origin turned about y
    T = locked.frame_pose("b", locked.q())
    np.testing.assert_allclose(T[:3, 3], [math.sin(middle), 0.0, math.cos(middle)], atol=1e-12)
