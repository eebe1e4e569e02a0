"""The contact simulation's verdict: static tipping angle, tilt and lift-off intervals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.analysis.stance import Stance, stance_of
from armcli.sim.liftoff import LIFT_CLEARANCE, lifts, roll_pitch_yaw, static_tipping_angle, tilt
from armcli.urdf.read import parse_urdf
from tests.helpers import FIXTURES

EXACT = 1e-12
FEET = ("foot_fl", "foot_fr", "foot_rl", "foot_rr")


def test_static_tipping_angle_of_the_box_on_feet() -> None:
    urdf = parse_urdf((FIXTURES / "tipover" / "box_rod.urdf").read_bytes(), "box_rod.urdf")
    stance = stance_of(urdf, declared=FEET)
    assert isinstance(stance, Stance)
    angle, direction = static_tipping_angle(stance, {"swing": 0.0})
    # centre of mass 1.1 / 6 m up over the middle; the feet at +-0.15 m sideways (the
    # nearer edges): atan(0.15 / h)
    assert angle == pytest.approx(math.atan2(0.15, 1.1 / 6.0), abs=1e-9)
    assert direction in ("left", "right")


def test_tilt_and_angles_of_known_rotations() -> None:
    a = 0.3
    about_y = np.array([[math.cos(a / 2), 0.0, math.sin(a / 2), 0.0]])  # (w, x, y, z)
    about_z = np.array([[math.cos(a / 2), 0.0, 0.0, math.sin(a / 2)]])
    assert tilt(about_y)[0] == pytest.approx(a, abs=EXACT)
    assert tilt(about_z)[0] == pytest.approx(0.0, abs=1e-7)  # turning is no tilt
    roll, pitch, yaw = roll_pitch_yaw(np.vstack([about_y, about_z]))
    assert (roll[0], pitch[0], yaw[0]) == pytest.approx((0.0, a, 0.0), abs=EXACT)
    assert (roll[1], pitch[1], yaw[1]) == pytest.approx((0.0, 0.0, a), abs=EXACT)


def test_a_lift_off_needs_no_force_and_clearance() -> None:
    t = np.arange(10) * 0.01
    force = np.array([30, 30, 0, 0, 0, 0, 30, 0, 0, 30], dtype=float)
    up = 2 * LIFT_CLEARANCE
    height = np.array([0.1, 0.1, 0.1 + up, 0.1 + up, 0.1 + up, 0.1, 0.1, 0.1, 0.1, 0.1])
    (lift,) = lifts("caster", t, force, height)  # steps 7-8: unloaded, but not off the ground
    assert (lift.start, lift.duration) == pytest.approx((0.02, 0.03), abs=EXACT)
    assert lift.height == pytest.approx(up, abs=EXACT)
