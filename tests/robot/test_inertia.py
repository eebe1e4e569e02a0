"""armcli.robot.inertia against independent references: numerical integration over the solid,
point clouds for frame changes, scipy for URDF's roll-pitch-yaw convention."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from armcli.robot import inertia as inr

# Midpoint quadrature with N cells per axis has O(1/N²) error: N = 60 gives ~1e-4.
QUADRATURE_RTOL = 5e-4
EXACT_RTOL = 1e-12
N = 60


def _integrate(points: np.ndarray, weights: np.ndarray, mass: float) -> np.ndarray:
    """Inertia tensor of a discretised solid of uniform density about its centroid."""
    w = weights / weights.sum() * mass
    c = (w[:, None] * points).sum(axis=0) / mass
    d = points - c
    r2 = (d * d).sum(axis=1)
    return np.einsum("i,ijk->jk", w, r2[:, None, None] * np.eye(3) - d[:, :, None] * d[:, None, :])


def _midpoints(lo: float, hi: float, n: int = N) -> np.ndarray:
    h = (hi - lo) / n
    return lo + h * (np.arange(n) + 0.5)


def test_box_matches_integration_over_the_solid() -> None:
    m, x, y, z = 2.0, 0.6, 0.4, 0.2
    g = np.stack(np.meshgrid(_midpoints(0, x), _midpoints(0, y), _midpoints(0, z)), -1)
    pts = g.reshape(-1, 3)
    ref = _integrate(pts, np.ones(len(pts)), m)
    np.testing.assert_allclose(inr.box_inertia(m, x, y, z), ref, rtol=QUADRATURE_RTOL, atol=1e-12)


def test_cylinder_axis_is_z_and_matches_integration() -> None:
    m, r, h = 0.3, 0.02, 0.3
    rr, th, zz = np.meshgrid(_midpoints(0, r), _midpoints(0, 2 * math.pi), _midpoints(0, h))
    pts = np.stack([rr * np.cos(th), rr * np.sin(th), zz], -1).reshape(-1, 3)
    ref = _integrate(pts, rr.reshape(-1), m)  # polar area element r dr dθ
    np.testing.assert_allclose(inr.cylinder_inertia(m, r, h), ref, rtol=QUADRATURE_RTOL, atol=1e-12)


def test_sphere_matches_integration() -> None:
    m, r = 0.5, 0.05
    rr, th, ph = np.meshgrid(_midpoints(0, r), _midpoints(0, math.pi), _midpoints(0, 2 * math.pi))
    pts = np.stack(
        [rr * np.sin(th) * np.cos(ph), rr * np.sin(th) * np.sin(ph), rr * np.cos(th)], -1
    ).reshape(-1, 3)
    ref = _integrate(pts, (rr**2 * np.sin(th)).reshape(-1), m)  # r² sinθ dr dθ dφ
    np.testing.assert_allclose(inr.sphere_inertia(m, r), ref, rtol=QUADRATURE_RTOL, atol=1e-12)


def test_parallel_axis_and_rotation_match_a_point_cloud() -> None:
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(500, 3)) * [0.3, 0.1, 0.05]
    w = rng.uniform(0.5, 1.5, size=500)
    m = 2.0
    J_c = _integrate(pts, w, m)
    wn = w / w.sum() * m
    c = (wn[:, None] * pts).sum(axis=0) / m
    # About the origin instead of the centroid: sum of m (|p|² I - p pᵀ) directly.
    about_origin = np.einsum(
        "i,ijk->jk",
        wn,
        (pts * pts).sum(1)[:, None, None] * np.eye(3) - pts[:, :, None] * pts[:, None, :],
    )
    np.testing.assert_allclose(inr.parallel_axis(J_c, m, c), about_origin, rtol=1e-10, atol=1e-14)
    R = Rotation.from_euler("xyz", [0.3, -0.7, 1.1]).as_matrix()
    np.testing.assert_allclose(
        inr.rotate(J_c, R), _integrate(pts @ R.T, w, m), rtol=1e-10, atol=1e-14
    )


def test_triangle_inequality_edges() -> None:
    # Thin rod along z: moments (I, I, 0) sit exactly on the bound; a flat plate
    # in the xy plane has Izz = Ixx + Iyy exactly; both are physical.
    rod = inr.cylinder_inertia(1.0, 1e-9, 1.0)
    plate = inr.box_inertia(1.0, 0.4, 0.2, 0.0)
    assert inr.satisfies_triangle(rod)
    assert inr.satisfies_triangle(plate)
    assert not inr.satisfies_triangle(np.diag([1.0, 1.0, 3.0]))
    assert inr.triangle_violation(np.diag([1.0, 1.0, 3.0])) == pytest.approx(1 / 3)


def test_positive_definite_and_symmetric() -> None:
    assert inr.is_positive_definite(np.diag([1.0, 2.0, 3.0]))
    assert not inr.is_positive_definite(np.diag([1.0, -2.0, 3.0]))
    assert not inr.is_positive_definite(np.diag([1.0, 2.0, math.nan]))
    # Off-diagonals larger than the diagonal allows: eigenvalues 1 +- 2 -> one negative.
    assert not inr.is_positive_definite(inr.tensor(1, 2, 0, 1, 0, 1))
    assert inr.is_symmetric(inr.tensor(1, 0.1, 0.2, 2, 0.3, 3))
    assert not inr.is_symmetric(np.array([[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]]))


def test_relative_difference_of_a_scaled_tensor() -> None:
    J = inr.box_inertia(5.0, 0.6, 0.4, 0.2)
    # |4J - J| / |4J| = 3/4 by definition of the Frobenius norm.
    assert inr.relative_difference(4 * J, J) == pytest.approx(0.75, rel=EXACT_RTOL)


sizes = st.floats(min_value=1e-3, max_value=10.0)


@settings(max_examples=60, deadline=None)
@given(m=sizes, a=sizes, b=sizes, c=sizes)
def test_every_solid_primitive_is_physical(m: float, a: float, b: float, c: float) -> None:
    for J in (inr.box_inertia(m, a, b, c), inr.cylinder_inertia(m, a, b), inr.sphere_inertia(m, a)):
        assert inr.is_positive_definite(J)
        assert inr.satisfies_triangle(J)
