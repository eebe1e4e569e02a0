"""Rigid-body inertia in pure numpy: primitive solids, frame changes, validity tests.

All tensors are 3x3 [kg·m²]. Primitive tensors are about the solid's centroid,
in the URDF geometry frame of that shape: a box's sides (x, y, z) lie along the
frame's x, y, z axes; a cylinder's axis is the frame's z axis (URDF convention).
The xacro writer and the `check` rules share these formulas, so generated
inertias and the inertia-versus-geometry rule cannot drift apart.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

Matrix = NDArray[np.float64]

# Relative tolerance for the triangle inequality on principal moments: a thin
# rod or plate sits exactly on the bound, so rounding must not flag it.
TRIANGLE_RTOL = 1e-6


def box_inertia(m: float, x: float, y: float, z: float) -> Matrix:
    """Solid box of mass m [kg] and full side lengths x, y, z [m] along the frame axes."""
    k = m / 12.0
    return np.diag([k * (y * y + z * z), k * (x * x + z * z), k * (x * x + y * y)])


def cylinder_inertia(m: float, r: float, h: float) -> Matrix:
    """Solid cylinder of mass m [kg], radius r [m], length h [m] along the z axis."""
    radial = m * (3.0 * r * r + h * h) / 12.0
    return np.diag([radial, radial, m * r * r / 2.0])


def sphere_inertia(m: float, r: float) -> Matrix:
    """Solid sphere of mass m [kg] and radius r [m]."""
    return np.eye(3) * (2.0 / 5.0) * m * r * r


def tensor(ixx: float, ixy: float, ixz: float, iyy: float, iyz: float, izz: float) -> Matrix:
    """The symmetric tensor from URDF's six `<inertia>` attributes."""
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


def rotate(J: Matrix, R: Matrix) -> Matrix:
    """Express a tensor given in frame B in frame A, where R = R_A_B: R J R^T."""
    return R @ J @ R.T


def parallel_axis(J_c: Matrix, m: float, d: Sequence[float]) -> Matrix:
    """Move a centroidal tensor to a point displaced by d [m] from the centroid (Steiner)."""
    dv = np.asarray(d, dtype=float)
    return J_c + m * (float(dv @ dv) * np.eye(3) - np.outer(dv, dv))


def is_symmetric(J: Matrix, rtol: float = 1e-9) -> bool:
    """True when J equals its transpose up to rtol of its largest entry."""
    scale = max(float(np.max(np.abs(J))), np.finfo(float).tiny)
    return bool(np.max(np.abs(J - J.T)) <= rtol * scale)


def principal_moments(J: Matrix) -> NDArray[np.float64]:
    """Eigenvalues of the symmetric part of J, ascending [kg·m²]."""
    return np.asarray(np.linalg.eigvalsh(0.5 * (J + J.T)), dtype=np.float64)


def is_positive_definite(J: Matrix) -> bool:
    """True when every principal moment is strictly positive."""
    return bool(np.all(np.isfinite(J)) and principal_moments(J)[0] > 0.0)


def triangle_violation(J: Matrix) -> float:
    """How far the largest principal moment exceeds the sum of the other two, relative.

    A physical body satisfies I3 <= I1 + I2 (equality for a flat plate); the
    result is (I3 - I1 - I2) / I3, so <= 0 is fine and > TRIANGLE_RTOL is not.
    """
    a, b, c = principal_moments(J)
    if c <= 0.0:
        return 0.0
    return float((c - a - b) / c)


def satisfies_triangle(J: Matrix, rtol: float = TRIANGLE_RTOL) -> bool:
    """True when the principal moments obey the triangle inequality within rtol."""
    return triangle_violation(J) <= rtol


def relative_difference(A: Matrix, B: Matrix) -> float:
    """Frobenius-norm difference of two tensors relative to the larger one."""
    tiny = np.finfo(float).tiny
    unit = max(float(np.max(np.abs(A))), float(np.max(np.abs(B))), tiny)
    A, B = np.asarray(A) / unit, np.asarray(B) / unit  # no overflow for absurd masses
    scale = max(float(np.linalg.norm(A)), float(np.linalg.norm(B)), tiny)
    return float(np.linalg.norm(A - B) / scale)
