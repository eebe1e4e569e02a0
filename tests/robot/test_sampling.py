"""armcli.robot.sampling: the shapes of the sample, its determinism, and followers following."""

from __future__ import annotations

import itertools
import math
import random

import numpy as np
import pytest

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


def test_many_joints_get_rest_corners_and_seeded_draws() -> None:
    box = [(0.5, 1.0), (-1.0, 1.0), (-2.0, 0.0), (-1.0, 1.0)]
    rows = sampling.joint_space(box)
    assert rows.shape == (1 + 2**4 + sampling.RANDOM_SAMPLES, 4)
    # the rest pose: 0 where the range holds it, else the middle, (0.5 + 1.0) / 2
    assert rows[0].tolist() == [0.75, 0.0, 0.0, 0.0]
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
    robot = Robot.load(parse_urdf(URDF, "t.urdf"))
    pairs = sampling.configurations(robot)
    # yaw continuous [-pi, pi], pitch [-1, 2], slide [0, 0.3]: 3 leaders, 125-point grid
    assert len(pairs) == sampling.GRID_POINTS**3
    for values, q in pairs:
        assert values["grip"] == 0.5 * values["slide"] + 0.01  # the URDF's <mimic>
        assert np.array_equal(q, robot.q(values))
    assert min(v["yaw"] for v, _ in pairs) == -math.pi


def chain_urdf(n: int) -> bytes:
    """A serial arm of n revolute joints (alternating axes y and z), 0.2 m, 1 kg links."""
    links = ['<link name="l0"/>']
    joints = []
    for i in range(1, n + 1):
        links.append(
            f'<link name="l{i}"><inertial><origin xyz="0 0 0.1"/><mass value="1"/>'
            '<inertia ixx="0.004" iyy="0.004" izz="0.001" ixy="0" ixz="0" iyz="0"/>'
            "</inertial></link>"
        )
        axis = "0 1 0" if i % 2 else "0 0 1"
        joints.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="0 0 {0.0 if i == 1 else 0.2}"/><axis xyz="{axis}"/>'
            f'<limit lower="{-1.0 - 0.1 * i}" upper="{1.5 + 0.1 * i}" effort="1000" '
            'velocity="2"/></joint>'
        )
    return f'<robot name="chain">{"".join(links + joints)}</robot>'.encode()


def test_check_and_tune_draw_identical_samples(monkeypatch: pytest.MonkeyPatch) -> None:
    """`check` (gravity, PD stability) and `tune` (start gains) size their verdicts on the
    same configurations: both ask `sampling.joint_space`, with the same box."""
    from armcli.check.options import CheckOptions
    from armcli.check.run import check_urdf
    from armcli.sim.simulate import simulated
    from armcli.tune.model_gains import start_gains

    seen: list[tuple[list[tuple[float, ...]], np.ndarray]] = []
    real = sampling.joint_space

    def recording(box: sampling.Bounds) -> np.ndarray:
        rows = real(box)
        seen.append(([tuple(b) for b in box], rows))
        return rows

    monkeypatch.setattr(sampling, "joint_space", recording)
    doc = parse_urdf(chain_urdf(5), "chain.urdf")  # 5 joints: draws, not the grid
    check_urdf(doc, CheckOptions())
    arm = simulated(Robot.load(doc))
    start_gains(arm, dt=1e-3, loop="implicit", zeta=1.0, wn_target=10.0, steps=np.ones(5))
    assert len(seen) == 2  # one sample for check, one for tune
    (box_check, rows_check), (box_tune, rows_tune) = seen
    assert box_check == box_tune == [(-1.0 - 0.1 * i, 1.5 + 0.1 * i) for i in range(1, 6)]
    assert rows_check.shape == (1 + 2**5 + sampling.RANDOM_SAMPLES, 5)
    assert np.array_equal(rows_check, rows_tune)
