"""gazebo_ros_diff_drive's controller and encoder odometry against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.drive.diffdrive import DiffDriveController, DriveParams, encoder_odometry
from armcli.errors import InputError
from armcli.spec.load import load_spec
from tests.helpers import DEFAULT_SPEC

EXACT = 1e-12
R, B = 0.1, 0.45  # [m] the course robot's wheel radius and separation


def params(accel: float = 1.0) -> DriveParams:
    return DriveParams("l", "r", B, R, 20.0, accel, 50.0, "odom", "base_footprint")


def test_the_spec_gives_the_plugins_parameters() -> None:
    p = DriveParams.of(load_spec(DEFAULT_SPEC))
    assert (p.left_joint, p.right_joint) == ("base_left_wheel_joint", "base_right_wheel_joint")
    assert (p.separation, p.radius, p.update_rate) == (0.45, 0.1, 50.0)
    assert (p.max_torque, p.max_accel) == (20.0, 1.0)  # the spec model's defaults


def test_a_spec_without_the_plugin_is_refused() -> None:
    spec = load_spec(DEFAULT_SPEC)
    base = spec.mobile_base.model_copy(update={"diff_drive": None})
    with pytest.raises(InputError) as info:
        DriveParams.of(spec.model_copy(update={"mobile_base": base}))
    assert info.value.field == "mobile_base.diff_drive"


def test_rim_speeds_ramp_at_the_acceleration_limit() -> None:
    c = DiffDriveController(params(accel=1.0))
    assert c.desired(0.2, 0.5) == pytest.approx((0.2 - 0.5 * B / 2, 0.2 + 0.5 * B / 2))
    period = 0.02
    # from rest: each update adds at most a * period to the instructed rim speed
    cmd = c.update(0.2, 0.0, np.zeros(2), period)
    assert cmd == pytest.approx([0.02 / R, 0.02 / R], abs=EXACT)
    # the instructed speed accumulates from its own value (the plugin's), measured 0.01 m/s
    cmd = c.update(0.2, 0.0, np.array([0.1, 0.1]), period)
    assert cmd == pytest.approx([0.04 / R, 0.04 / R], abs=EXACT)
    # one wheel within 0.01 m/s of its target: both go on ramping (ROS 2; ROS 1 jumped)
    cmd = c.update(0.2, 0.0, np.array([0.195 / R, 0.1 / R]), period)
    assert cmd == pytest.approx([(0.04 + 0.005) / R, (0.04 + 0.02) / R], abs=EXACT)
    # both within 0.01 m/s: both are commanded their targets
    cmd = c.update(0.2, 0.0, np.array([0.195 / R, 0.192 / R]), period)
    assert cmd == pytest.approx([2.0, 2.0], abs=EXACT)


def test_without_a_limit_the_targets_are_commanded_at_once() -> None:
    cmd = DiffDriveController(params(accel=0.0)).update(0.0, 1.0, np.zeros(2), 0.02)
    assert cmd == pytest.approx([-B / 2 / R, B / 2 / R], abs=EXACT)


def test_odometry_straight_turn_and_arc() -> None:
    dt, n = 1e-3, 2000
    w = np.full(n, 3.0)  # [rad/s]
    o = encoder_odometry(w, w, dt, R, B)  # straight: x = R w t
    assert (o.x[-1], o.y[-1], o.yaw[-1]) == pytest.approx((R * 3.0 * n * dt, 0.0, 0.0), abs=1e-12)
    assert o.linear[-1] == pytest.approx(R * 3.0)
    o = encoder_odometry(-w, w, dt, R, B)  # in place: yaw = 2 R w t / b, no translation
    assert o.yaw[-1] == pytest.approx(2 * R * 3.0 * n * dt / B, abs=1e-12)
    assert abs(o.x[-1]) < 1e-12 and abs(o.y[-1]) < 1e-12
    assert o.angular[-1] == pytest.approx(2 * R * 3.0 / B)
    # an arc of radius rho = b/2 (vl + vr)/(vr - vl): the midpoint rule's chord error is
    # O(dθ²) per step, 1e-9 m here
    vl, vr = 2.0, 4.0
    o = encoder_odometry(np.full(n, vl), np.full(n, vr), dt, R, B)
    theta = R * (vr - vl) / B * n * dt
    rho = B / 2 * (vl + vr) / (vr - vl)
    assert o.yaw[-1] == pytest.approx(theta, abs=1e-12)
    assert (o.x[-1], o.y[-1]) == pytest.approx((rho * math.sin(theta), rho * (1 - math.cos(theta))),
                                               abs=1e-6)  # fmt: skip
