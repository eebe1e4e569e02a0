"""Plan's own output is not hostile input: a 60 s plan certifies, writes and simulate reads it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.errors import InputError
from armcli.io.yaml import MAX_YAML_BYTES
from armcli.plan.certify import certify
from armcli.plan.inputs import Loaded
from armcli.plan.output import read_back, trajectory_yaml
from armcli.plan.timing import Timed
from armcli.trajectory.message import load_trajectory

DURATION_S = 60.0  # issue 36: "a 60 s plan certifies and writes"
RATE_HZ = 100.0  # plan.timing.OUTPUT_RATE_HZ


def slow_motion(robot: object, duration: float) -> Timed:
    """A smooth rest-to-rest swing of every joint by 0.3 rad over `duration` [s]."""
    t = np.linspace(0.0, duration, int(duration * RATE_HZ) + 1)
    u = (t / duration)[:, None]
    start = 0.5 * (robot.lower + robot.upper)  # type: ignore[attr-defined]
    d = np.full(len(start), 0.3)
    q = start + d * (10 * u**3 - 15 * u**4 + 6 * u**5)
    qd = d * (30 * u**2 - 60 * u**3 + 30 * u**4) / duration
    qdd = d * (60 * u - 180 * u**2 + 120 * u**3) / duration**2
    return Timed(t, q, qd, qdd)


def test_a_60_s_plan_reads_back_certifies_and_simulate_reads_it(
    panda: Loaded, tmp_path: Path
) -> None:
    robot = panda.context.robot
    doc = trajectory_yaml(robot.joints, slow_motion(robot, DURATION_S), frame_id="world")
    assert len(doc) > MAX_YAML_BYTES  # beyond the cap for files users give
    limits = {n: (float(lo), float(hi)) for n, lo, hi in zip(robot.joints, robot.lower,
                                                            robot.upper, strict=True)}  # fmt: skip
    back = read_back(doc, limits)
    assert back.duration == pytest.approx(DURATION_S)
    assert certify(robot, panda.context.checker, back) is None
    path = tmp_path / "plan.yaml"
    path.write_bytes(doc)
    traj = load_trajectory(path, limits)  # simulate's reading of the written file
    assert np.array_equal(traj.positions, back.positions)


def test_a_large_file_in_another_layout_is_still_capped(panda: Loaded, tmp_path: Path) -> None:
    robot = panda.context.robot
    doc = trajectory_yaml(robot.joints, slow_motion(robot, DURATION_S), frame_id="world")
    path = tmp_path / "edited.yaml"
    path.write_bytes(doc.replace(b"points:", b"points:  # edited by hand", 1))
    limits = {n: (float(lo), float(hi)) for n, lo, hi in zip(robot.joints, robot.lower,
                                                            robot.upper, strict=True)}  # fmt: skip
    with pytest.raises(InputError, match=f"larger than {MAX_YAML_BYTES} bytes"):
        load_trajectory(path, limits)
