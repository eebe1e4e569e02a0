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
