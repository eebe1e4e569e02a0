"""Sensors on the arm in a fixed-base run (no drive): replayed from the engine's states.

The course arm holding a pose: an IMU on the hand reads gravity in the hand's frame, the
hand turned by q1 + q2 about y (both joints' axes are y): specific force
(-g sin(q1 + q2), 0, g cos(q1 + q2)), and its orientation is that turn. A depth camera
on the hand's tip looking straight down at the floor under the root (z = 0) sees it at
the tip's height (forward kinematics by hand: 0.02 + 0.3 cos q1 + 0.3 cos(q1 + q2) ...).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from armcli.sim.armrun import simulate_arm
from armcli.sim.options import SimOptions
from tests.helpers import DEFAULT_SPEC, spec_file

pytest.importorskip("mujoco")

G = 9.81
ACC_TOL = 0.01  # [m/s²] the bound (the arm settles within friction / Kp)
Q = (0.5, 0.3)  # [rad] the held pose
DEPTH_TOL = 0.01  # [m] the hold's sag (friction / Kp: 0.05 / 50 rad) moves the tip by mm


def _spec(tmp_path: Path) -> Path:
    sensors = {
        "hand_imu": {"type": "imu", "link": "hand_link", "rate": 50, "topic": "imu"},
        "tip_depth": {"type": "depth_camera", "link": "hand_link", "rate": 5, "topic": "tip",
                      "origin": {"xyz": [0, 0, 0.32]},
                      "camera": {"width": 32, "height": 24, "horizontal_fov": 0.5,
                                 "near": 0.01, "far": 5.0}},
    }  # fmt: skip
    path = tmp_path / "arm.yaml"
    path.write_text(DEFAULT_SPEC.read_text() + "\n" + yaml.safe_dump({"sensors": sensors}))
    return path


def test_an_imu_and_a_depth_camera_on_the_hand(tmp_path: Path) -> None:
    file = spec_file(_spec(tmp_path))
    hold = ("joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
            f" - {{positions: [{Q[0]}, {Q[1]}], time_from_start: 1.0}}\n")  # fmt: skip
    run = simulate_arm(file, SimOptions(message=hold, duration=3.0, gravity_comp=True))
    imu = next(r for r in run.readings if r.name == "hand_imu")
    assert len(imu.time) == 151  # 50 Hz over 3 s
    late = imu.data["imu"][imu.time >= 2.5]
    theta = sum(Q)
    expected = [-G * math.sin(theta), 0.0, G * math.cos(theta)]
    assert np.max(np.abs(late[:, 7:10] - expected)) < ACC_TOL
    assert np.max(np.abs(late[:, 4:7])) < ACC_TOL
    # the hand's orientation: a turn of theta about y, as (x, y, z, w)
    np.testing.assert_allclose(late[-1, :4], [0, math.sin(theta / 2), 0, math.cos(theta / 2)],
                               atol=1e-3)  # fmt: skip
    depth = next(r for r in run.readings if r.name == "tip_depth")
    # the camera above the floor: base 0.02, forearm 0.3 up at q1, 0.32 of hand up at
    # q1 + q2; its axis, the hand's x, points down by theta: the centre ray meets z = 0 at
    # height / sin(theta) along it
    height = 0.02 + 0.3 * math.cos(Q[0]) + 0.32 * math.cos(theta)
    centre = depth.data["depth"][-1][11:13, 15:17].mean()
    assert centre == pytest.approx(height / math.sin(theta), abs=DEPTH_TOL)
