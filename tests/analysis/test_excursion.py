"""The tipping bound of a zero-moment-point excursion against a hand computation.

The box-on-feet fixture (tests/fixtures/tipover/box_rod.urdf) standing still with its rod
upright, pushed by a steady base acceleration until its zero-moment point is 10 mm past
the rear feet: the bound √(2 I_edge m g (√(d² + h²) − h)) / (m g) from the URDF's numbers,
the inertia about the edge summed body by body with the parallel-axis theorem.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.analysis import zmp as zmps
from armcli.analysis.excursion import excursions
from armcli.analysis.stance import Stance, stance_of
from armcli.urdf.read import parse_urdf
from tests.helpers import FIXTURES

G = 9.81  # [m/s²] Pinocchio's
EXACT = 1e-9
FEET = ("foot_fl", "foot_fr", "foot_rl", "foot_rr")


def hand_bound() -> float:
    """Rear edge x = -0.2 m on the ground, along y; rod upright; numbers from the URDF."""
    bodies = [  # (mass [kg], x, z [m] of its centre of mass, I_yy about it [kg·m²])
        (4.0, 0.0, 0.1, 0.056666666666666664),  # box
        *[(0.25, x, 0.05, 0.00025) for x in (0.2, 0.2, -0.2, -0.2)],  # feet
        (1.0, 0.0, 0.65, 0.0001),  # the rod's ball: 0.1 + 0.05 + 0.5 up
    ]
    m = sum(b[0] for b in bodies)
    i_edge = sum(i + mb * ((x + 0.2) ** 2 + z**2) for mb, x, z, i in bodies)
    h = sum(mb * z for mb, _, z, _ in bodies) / m  # 1.1 / 6 m
    d = 0.2  # the centre of mass is over the box's centre
    barrier = m * G * (math.hypot(d, h) - h)
    return math.sqrt(2 * i_edge * barrier) / (m * G)  # 0.0490 m·s


@pytest.fixture(scope="module")
def stance() -> Stance:
    urdf = parse_urdf((FIXTURES / "tipover" / "box_rod.urdf").read_bytes(), "box_rod.urdf")
    found = stance_of(urdf, declared=FEET)
    assert isinstance(found, Stance)
    return found


def steady(stance: Stance, seconds: float, outside: float) -> zmps.ZmpSeries:
    """The robot at rest for `seconds`, its base accelerating so that the point is
    `outside` [m] behind the rear feet: x_zmp = -h a / g."""
    h = 1.1 / 6.0
    accel = (0.2 + outside) * G / h
    dt, n = 1e-3, round(seconds / 1e-3) + 1
    step = np.arange(n)
    zeros = np.zeros((n, 1))
    return zmps.zmp_series(stance, ("swing",), step * dt, step, zeros, zeros, dt, accel, 0.0)


def test_the_bound_is_the_hand_computed_one(stance: Stance) -> None:
    series = steady(stance, 1.0, 0.01)
    # accelerating pushes the point past the rear feet, braking as far past the front ones
    back, front = excursions(stance, series)
    assert (back.case, back.direction, front.case, front.direction) == (
        "accelerating", "rear", "braking", "front")  # fmt: skip
    assert front.bound == pytest.approx(back.bound, rel=1e-12)  # the box is symmetric
    ex = back
    assert ex.depth == pytest.approx(0.01, abs=1e-9)
    assert ex.bound == pytest.approx(hand_bound(), rel=1e-9)
    assert ex.impulse == pytest.approx(0.01 * 1.0, rel=1e-9)  # e x the time outside
    assert not ex.tips  # 0.01 m·s of the 0.049 it takes


def test_a_long_enough_excursion_tips(stance: Stance) -> None:
    ex, _ = excursions(stance, steady(stance, 6.0, 0.01))  # 0.06 m·s > 0.049 m·s
    assert ex.tips and ex.impulse == pytest.approx(0.06, rel=1e-9)
