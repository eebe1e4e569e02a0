"""The all-mass-on-the-extremes bounds behind `inertia-exceeds-geometry`, against point-mass
distributions summed by hand (independent of the formulas) and seeded random ones."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from armcli.robot.frames import rpy_matrix
from armcli.robot.inertia_bounds import (
    EXCEEDS_RTOL,
    excess,
    extreme_bound,
    fix_values,
    solid_inertia,
)
from armcli.urdf.doc import Geometry

BOX = Geometry("box", (0.6, 0.4, 0.2), None)
CYLINDER = Geometry("cylinder", (0.1, 0.05), None)  # radius, length (axis z)
SPHERE = Geometry("sphere", (0.05,), None)
MASS = 2.0  # [kg]
RTOL = 1e-12  # sums of a few products: exact to rounding
SEED = 14
SAMPLES = 200


def point_inertia(points: list[tuple[float, float, float]], m: float) -> np.ndarray:
    """Inertia about the origin of equal point masses summing to m: sum m_i (|r|² 1 - r rᵀ)."""
    J = np.zeros((3, 3))
    for p in points:
        r = np.asarray(p)
        J += m / len(points) * (float(r @ r) * np.eye(3) - np.outer(r, r))
    return J


def test_box_bound_is_reached_by_mass_on_the_corners() -> None:
    a, b, c = (x / 2 for x in BOX.dims or ())
    corners = [(sx * a, sy * b, sz * c) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    # Every corner is farthest from every axis: the bound is reached on all three at once.
    assert np.diag(point_inertia(corners, MASS)) == pytest.approx(
        extreme_bound(BOX, MASS), rel=RTOL
    )
    # ... and it is three times the solid box (m (b² + c²)/12 vs m (b² + c²)/4).
    assert extreme_bound(BOX, MASS) == pytest.approx(
        3 * np.diag(solid_inertia(BOX, MASS)), rel=RTOL
    )


def test_cylinder_bounds_are_reached_axis_by_axis() -> None:
    r, h = (CYLINDER.dims or ())[0], (CYLINDER.dims or ())[1] / 2
    rim = [(r * math.cos(t), r * math.sin(t), 0.0) for t in np.linspace(0, 2 * math.pi, 8, False)]
    far_x = [(0.0, sy * r, sz * h) for sy in (-1, 1) for sz in (-1, 1)]
    bound = extreme_bound(CYLINDER, MASS)
    assert point_inertia(rim, MASS)[2, 2] == pytest.approx(bound[2], rel=RTOL)  # m r²
    assert point_inertia(far_x, MASS)[0, 0] == pytest.approx(bound[0], rel=RTOL)  # m(r²+l²/4)


def test_sphere_bound_is_reached_by_the_poles() -> None:
    r = (SPHERE.dims or ())[0]
    poles = [(0.0, 0.0, r), (0.0, 0.0, -r)]
    assert point_inertia(poles, MASS)[0, 0] == pytest.approx(extreme_bound(SPHERE, MASS)[0])


def _inside(g: Geometry, rng: random.Random) -> tuple[float, float, float]:
    d = g.dims or ()
    while True:
        if g.kind == "box":
            return (
                rng.uniform(-d[0], d[0]) / 2,
                rng.uniform(-d[1], d[1]) / 2,
                rng.uniform(-d[2], d[2]) / 2,
            )
        p = (rng.uniform(-d[0], d[0]), rng.uniform(-d[0], d[0]), 0.0)
        if g.kind == "cylinder":
            p = (p[0], p[1], rng.uniform(-d[1], d[1]) / 2)
            if p[0] ** 2 + p[1] ** 2 <= d[0] ** 2:
                return p
        else:
            p = (p[0], p[1], rng.uniform(-d[0], d[0]))
            if sum(x * x for x in p) <= d[0] ** 2:
                return p


@pytest.mark.parametrize("g", [BOX, CYLINDER, SPHERE], ids=lambda g: g.kind)
def test_no_distribution_inside_exceeds_the_bound(g: Geometry) -> None:
    """Random clouds of 1-8 points inside the shape, centroidal inertia and COM offset as a
    URDF would write them: never flagged (the rule has no false positives)."""
    rng = random.Random(SEED)
    for _ in range(SAMPLES):
        pts = [_inside(g, rng) for _ in range(rng.randint(1, 8))]
        com = np.mean(np.asarray(pts), axis=0)
        J_com = point_inertia([tuple(np.asarray(p) - com) for p in pts], MASS)
        assert excess(J_com, MASS, com, g).axes == ()


def test_com_offset_makes_the_bound_sharper() -> None:
    """0.9x the bound about the COM passes at the centre, fails with the COM at a face:
    moved to the shape centre by the parallel-axis theorem it is over the bound."""
    J = np.diag(0.9 * extreme_bound(BOX, MASS))
    assert excess(J, MASS, np.zeros(3), BOX).axes == ()
    face = np.array([(BOX.dims or ())[0] / 2, 0.0, 0.0])  # the COM on the +x face
    # m (a/2)² = 0.18 kg m² is added to I_yy (0.9 x 0.2) and I_zz (0.9 x 0.26), not to I_xx.
    assert excess(J, MASS, face, BOX).axes == ("y", "z")


def test_tolerance_covers_a_thin_tube_written_with_4_digits() -> None:
    r = (CYLINDER.dims or ())[0]
    tube = MASS * r * r * (1 + 0.5 * EXCEEDS_RTOL)  # a tube's I_axis, slightly over-rounded
    J = np.diag([1e-4, 1e-4, tube])
    assert excess(J, MASS, np.zeros(3), CYLINDER).axes == ()


def test_fix_values_rotate_into_the_inertial_frame() -> None:
    """A wheel whose geometry is rolled 90 deg about x while the inertial frame is not:
    the solid cylinder's axis moment (m r²/2) must land on iyy."""
    R_geom_inertial = rpy_matrix((math.pi / 2, 0.0, 0.0)).T
    fix = fix_values(solid_inertia(CYLINDER, MASS), R_geom_inertial)
    r = (CYLINDER.dims or ())[0]
    assert fix["iyy"] == pytest.approx(MASS * r * r / 2, rel=1e-3)
    assert fix["ixy"] == fix["ixz"] == fix["iyz"] == 0.0
