"""Bounds on the moments of inertia a mass inside a primitive shape can have.

The numbers behind `inertia-exceeds-geometry`, and the solid-body inertia to write instead.

Why a bound and not a tolerance: a hollow part legitimately has more inertia than the
solid formula (a tube, a shell), so "differs from the solid" is only a warning. But no
mass distribution inside a shape can exceed the moment it has with all the mass on the
points farthest from the axis: about an axis through the shape's centre, every mass
element m_i sits at distance <= rho_max from the axis, so I <= m rho_max². For a box
a x b x c that is I_xx <= m (b² + c²) / 4 (three times the solid value m (b² + c²) / 12);
for a cylinder of radius r and length l, I_axis <= m r² and I_transverse <= m (r² + l²/4);
for a sphere, I <= m r². The URDF gives the inertia about the centre of mass, which by
the parallel-axis theorem is never larger than about the shape's centre:
I_centre = I_com + m (|d|² 1 - d dᵀ), so the comparison is made about the centre.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from armcli.robot import inertia as inr
from armcli.urdf.doc import Geometry, Link, Shape

Matrix = NDArray[np.float64]

# Above the bound by more than this fraction counts: a thin-walled tube sits exactly on
# I_axis = m r², and values written with 3-4 significant digits may overshoot it by < 1 %.
EXCEEDS_RTOL = 0.01
# Significant digits of the suggested inertia values (the URDF then matches the formula
# to well within INERTIA_GEOMETRY_RTOL).
FIX_DIGITS = 4
AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Excess:
    """The moments about the shape's centre that no mass inside the shape can reach."""

    axes: tuple[str, ...]  # geometry-frame axes whose moment is above the bound
    centre: tuple[float, float, float]  # diag of the inertia about the shape centre [kg·m²]
    bound: tuple[float, float, float]  # all-mass-on-the-extremes bound [kg·m²]
    solid: tuple[float, float, float]  # the solid body's moments [kg·m²]


def collision_primitive(link: Link) -> Shape | None:
    """The link's collision geometry when it is exactly one box, cylinder or sphere."""
    if len(link.collisions) != 1:
        return None
    shape = link.collisions[0]
    g = shape.geometry
    if g is None or g.kind not in ("box", "cylinder", "sphere") or g.dims is None:
        return None
    return shape if all(d > 0 for d in g.dims) else None


def extreme_bound(g: Geometry, m: float) -> NDArray[np.float64]:
    """Largest moment [kg·m²] about each geometry axis through the centre, for mass m inside g."""
    d = g.dims or ()
    if g.kind == "box":
        hx, hy, hz = (x / 2.0 for x in d)
        return m * np.array([hy**2 + hz**2, hx**2 + hz**2, hx**2 + hy**2])
    if g.kind == "cylinder":
        r, half = d[0], d[1] / 2.0
        return m * np.array([r**2 + half**2, r**2 + half**2, r**2])
    return m * np.full(3, d[0] ** 2)


def solid_inertia(g: Geometry, m: float) -> Matrix:
    """The centroidal inertia of a solid primitive in its geometry frame."""
    d = g.dims or ()
    if g.kind == "box":
        return inr.box_inertia(m, d[0], d[1], d[2])
    if g.kind == "cylinder":
        return inr.cylinder_inertia(m, d[0], d[1])
    return inr.sphere_inertia(m, d[0])


def excess(J_geom: Matrix, m: float, com_offset: NDArray[np.float64], g: Geometry) -> Excess:
    """Compare the inertia about the shape centre with the bound, axis by axis.

    Args:
        J_geom: the centroidal inertia [kg·m²] expressed in the geometry frame.
        m: the mass [kg].
        com_offset: centre of mass minus shape centre [m], in the geometry frame.
        g: the primitive.
    """
    about_centre = np.diag(inr.parallel_axis(J_geom, m, [float(x) for x in com_offset]))
    bound = extreme_bound(g, m)
    over = tuple(
        a for a, i, b in zip(AXES, about_centre, bound, strict=True) if i > b * (1 + EXCEEDS_RTOL)
    )
    return Excess(over, _t3(about_centre), _t3(bound), _t3(np.diag(solid_inertia(g, m))))


def fix_values(solid_geom: Matrix, R_geom_inertial: Matrix) -> dict[str, float]:
    """The solid tensor as URDF attributes of the link's <inertia> (in the inertial frame).

    Args:
        solid_geom: the tensor in the geometry frame [kg·m²].
        R_geom_inertial: rotation from the inertial frame to the geometry frame.
    """
    J = inr.rotate(solid_geom, R_geom_inertial.T)
    scale = float(np.max(np.abs(J))) or 1.0
    out = {}
    for name, (i, k) in zip(
        ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"),
        ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)),
        strict=True,
    ):
        v = float(J[i, k])
        out[name] = 0.0 if abs(v) < 1e-12 * scale else float(f"{v:.{FIX_DIGITS}g}")
    return out


def fix_text(fix: dict[str, float]) -> str:
    """`ixx="..." ixy="..." ...` ready to paste into the <inertia> element."""
    return " ".join(f'{k}="{v:g}"' for k, v in fix.items())


def _t3(v: NDArray[np.float64]) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
