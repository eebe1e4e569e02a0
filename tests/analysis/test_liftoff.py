"""The contact simulation's verdict: static tipping angle, tilt and lift-off intervals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.analysis.liftoff import (
    LIFT_CLEARANCE,
    edge_tilts,
    lifts,
    static_tipping_angle,
    tipping_angles,
    verdict,
)
from armcli.analysis.stance import Stance, stance_of
from armcli.urdf.read import parse_urdf
from tests.helpers import FIXTURES

EXACT = 1e-12
FEET = ("foot_fl", "foot_fr", "foot_rl", "foot_rr")


def _box() -> Stance:
    urdf = parse_urdf((FIXTURES / "tipover" / "box_rod.urdf").read_bytes(), "box_rod.urdf")
    stance = stance_of(urdf, declared=FEET)
    assert isinstance(stance, Stance)
    return stance


def _pitch(angles: np.ndarray) -> np.ndarray:
    """(w, x, y, z) rows of rotations about y: positive tips the base toward +x (front)."""
    return np.column_stack([np.cos(angles / 2), 0 * angles, np.sin(angles / 2), 0 * angles])


def test_static_tipping_angle_of_the_box_on_feet() -> None:
    stance = _box()
    angle, direction = static_tipping_angle(stance, {"swing": 0.0})
    # centre of mass 1.1 / 6 m up over the middle; the feet at +-0.15 m sideways (the
    # nearer edges): atan(0.15 / h)
    assert angle == pytest.approx(math.atan2(0.15, 1.1 / 6.0), abs=1e-9)
    assert direction in ("left", "right")


def test_a_lift_off_needs_no_force_and_clearance() -> None:
    t = np.arange(10) * 0.01
    force = np.array([30, 30, 0, 0, 0, 0, 30, 0, 0, 30], dtype=float)
    up = 2 * LIFT_CLEARANCE
    height = np.array([0.1, 0.1, 0.1 + up, 0.1 + up, 0.1 + up, 0.1, 0.1, 0.1, 0.1, 0.1])
    (lift,) = lifts("caster", t, force, height)  # steps 7-8: unloaded, but not off the ground
    assert (lift.start, lift.duration) == pytest.approx((0.02, 0.03), abs=EXACT)
    assert lift.height == pytest.approx(up, abs=EXACT)


def test_each_edge_has_its_own_tipping_angle_and_tilt() -> None:
    stance = _box()
    h = 1.1 / 6.0  # the centre of mass's height (test above)
    by_edge = dict(zip((e.direction for e in stance.polygon.edges),
                       tipping_angles(stance, {"swing": 0.0}), strict=True))  # fmt: skip
    # feet at x = +-0.2 m, y = +-0.15 m around the centre of mass: atan(d / h) per edge
    assert by_edge["front"] == pytest.approx(math.atan2(0.2, h), abs=1e-9)
    assert by_edge["left"] == pytest.approx(math.atan2(0.15, h), abs=1e-9)
    a = 0.3
    normals = stance.polygon.normals
    toward = dict(zip((e.direction for e in stance.polygon.edges),
                      edge_tilts(_pitch(np.array([a])), normals)[0], strict=True))  # fmt: skip
    # a pitch about y is a rotation about the front and rear edges' axes, none about the sides'
    assert (toward["front"], toward["rear"]) == pytest.approx((a, -a), abs=EXACT)
    assert (toward["left"], toward["right"]) == pytest.approx((0.0, 0.0), abs=EXACT)
    roll = np.array([[math.cos(a / 2), math.sin(a / 2), 0.0, 0.0]])  # about x: +y goes up
    toward = dict(zip((e.direction for e in stance.polygon.edges),
                      edge_tilts(roll, normals)[0], strict=True))  # fmt: skip
    assert (toward["right"], toward["left"]) == pytest.approx((a, -a), abs=EXACT)


def test_a_tilt_toward_an_edge_is_measured_against_that_edges_angle() -> None:
    """Past the side edges' 39.3 deg, not the front's 47.5: a pitch of 42 deg rocks back."""
    stance = _box()
    t = np.linspace(0.0, 2.0, 201)
    front = math.atan2(0.2, 1.1 / 6.0)
    forward = np.radians(42.0) * np.sin(np.pi * t / 2.0)  # forward and back, under 47.5 deg
    v = verdict(stance, {"swing": 0.0}, t, _pitch(forward), {})
    assert not v.tips and not v.rocks
    assert v.direction == "front" and v.worst_tilt == pytest.approx(np.radians(42.0), abs=1e-6)
    assert v.static_angle == pytest.approx(math.atan2(0.15, 1.1 / 6.0), abs=1e-9)  # the sides'

    rock = np.where(t < 1.0, (front + 0.1) * np.sin(np.pi * t), 0.0)  # past it, then back
    v = verdict(stance, {"swing": 0.0}, t, _pitch(rock), {})
    assert not v.tips
    (r,) = v.rocks
    assert r.direction == "front" and r.peak == pytest.approx(front + 0.1, abs=1e-3)
    assert r.line() in v.notes()

    fall = np.where(t < 1.0, rock, front + 0.5)  # rocks, then goes over and stays there
    v = verdict(stance, {"swing": 0.0}, t, _pitch(fall), {})
    assert v.tips and v.direction == "front" and len(v.rocks) == 1
    assert v.tip_time == pytest.approx(1.0, abs=0.01)  # the excursion it did not come back from
