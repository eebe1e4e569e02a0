"""armcli.robot.sampling: the shapes of the sample, its determinism, and followers following."""

from __future__ import annotations

import itertools
import math
import random

import numpy as np

from armcli.robot import sampling
from armcli.robot.model import Robot
from armcli.urdf.read import parse_urdf
from tests.robot.test_model import URDF


def test_few_joints_get_the_full_grid() -> None:
    box = [(-1.0, 1.0), (0.0, 2.0), (-3.0, 3.0)]
    rows = sampling.joint_space(box)
    # 5 points per joint (GRID_POINTS), evenly spaced ends included: 5**3 = 125 rows
    axis = [np.array([lo, lo + (hi - lo) / 4, (lo + hi) / 2, hi - (hi - lo) / 4, hi])
            for lo, hi in box]  # fmt: skip
    assert np.allclose(rows, np.array(list(itertools.product(*axis))), rtol=0, atol=1e-15)


def test_many_joints_get_zero_corners_and_seeded_draws() -> None:
    box = [(0.5, 1.0), (-1.0, 1.0), (-2.0, 0.0), (-1.0, 1.0)]
    rows = sampling.joint_space(box)
    assert rows.shape == (1 + 2**4 + sampling.RANDOM_SAMPLES, 4)
    assert rows[0].tolist() == [0.5, 0.0, 0.0, 0.0]  # 0 clamped into each range
    assert {tuple(r) for r in rows[1:17]} == set(itertools.product(*box))
    # the draws: the standard library's generator, seeded, one row after the other
    rng = random.Random(sampling.SAMPLE_SEED)
    first = [rng.uniform(lo, hi) for lo, hi in box]
    assert rows[17].tolist() == first
    lo, hi = np.array(box).T
    assert np.all((rows >= lo) & (rows <= hi))
    assert np.array_equal(rows, sampling.joint_space(box))  # same box, same sample


def test_many_corners_are_left_out() -> None:
    box = [(-1.0, 1.0)] * 7  # 128 corners > MAX_CORNERS
    assert sampling.corners(box) == []
    assert len(sampling.joint_space(box)) == 1 + sampling.RANDOM_SAMPLES


def test_search_starts_order() -> None:
    box = [(-1.0, 1.0), (0.0, 1.0)]
    starts = sampling.search_starts(box, 3, named=[[0.5, 0.5]])
    assert starts[:2] == [[0.0, 0.0], [0.5, 0.5]]
    assert starts[2:6] == [[-1.0, 0.0], [-1.0, 1.0], [1.0, 0.0], [1.0, 1.0]]
    assert starts[6:] == sampling.draws(box, 3)


def test_followers_follow_their_leaders() -> None:
    robot = Robot.from_urdf(parse_urdf(URDF, "t.urdf"))
    pairs = sampling.configurations(robot)
    # yaw continuous [-pi, pi], pitch [-1, 2], slide [0, 0.3]: 3 leaders, 125-point grid
    assert len(pairs) == sampling.GRID_POINTS**3
    for values, q in pairs:
        assert values["grip"] == 0.5 * values["slide"] + 0.01  # the URDF's <mimic>
        assert np.array_equal(q, robot.q(values))
    assert min(v["yaw"] for v, _ in pairs) == -math.pi
