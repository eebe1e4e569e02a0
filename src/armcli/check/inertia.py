"""Inertia rules: mass sign, positive definiteness, triangle inequality, own geometry.

Comparing the inertia with the link's own geometry catches permuted or scaled macro output.
"""

from __future__ import annotations

import itertools

import numpy as np

from armcli.check.findings import Collector
from armcli.check.structure import finite
from armcli.robot import inertia as inr
from armcli.robot import inertia_bounds as bounds
from armcli.robot.frames import rpy_matrix
from armcli.urdf.doc import Inertial, Link, Shape, Urdf
from armcli.urdf.tree import KinematicTree

# Inertia within 5 % (Frobenius, relative) of the solid-body formula counts as
# "from the geometry"; real macro bugs (permuted axes, 4x) are off by >= 50 %.
INERTIA_GEOMETRY_RTOL = 0.05
# Centre of mass within 1 mm + 1 % of the shape's largest size of its centre.
COM_ATOL = 1e-3
COM_RTOL = 0.01
# A link with mass needs principal moments above this [kg·m²] (MuJoCo's mjMINVAL):
# zero is a point mass or an infinitely thin rod, and rounding noise on an
# all-zero tensor (1e-20) must not pass as "positive".
MIN_MOMENT = 1e-15
# A tensor that is not all zeros but whose principal moments are all within
# max(MIN_MOMENT, ZERO_RTOL * m * L²) of zero (L: the link's size, see _size) is
# rounding noise, not a body: iCub's ankles write ixz = 1.36e-20 and nothing else.
# MuJoCo rejects such a tensor ("inertia must have positive eigenvalues"); so does
# this rule. 1e-9 m L² is the moment of a rod 3e-5 L thick: no real part is thinner.
ZERO_RTOL = 1e-9


def check(urdf: Urdf, tree: KinematicTree, out: Collector) -> None:
    """Per-link rules; the bodies the joints move are checked in check/bodies.py."""
    for link in urdf.links:
        ine = link.inertial
        if ine is None:
            if tree.is_moving(link.name) and (link.visuals or link.collisions):
                out.add(
                    "missing-inertial",
                    link.line,
                    f"moving link {link.name!r} has geometry but no <inertial> (massless)",
                    link=link.name,
                )
            continue
        if link.name == tree.root and finite(ine.mass) and ine.mass > 0:  # type: ignore[operator]
            out.add(
                "root-inertia",
                ine.line,
                f"root link {link.name!r} has mass {ine.mass:g} kg; "
                "KDL (robot_state_publisher) ignores root inertia",
                mass=ine.mass,
            )
        if _mass_ok(link, ine, out):
            J = _tensor_ok(link, ine, out)
            if J is not None:
                _versus_geometry(link, ine, J, out)


def _mass_ok(link: Link, ine: Inertial, out: Collector) -> bool:
    m = ine.mass
    if m is None or not finite(m):
        return False
    if m < 0:
        out.add(
            "mass-nonpositive",
            ine.mass_line,
            f"link {link.name!r}: negative mass {m:g} kg",
            link=link.name,
            mass=m,
        )
        return False
    return m > 0


def _tensor_ok(link: Link, ine: Inertial, out: Collector) -> np.ndarray | None:
    """The link's tensor if it is positive definite and obeys the triangle inequality."""
    if ine.inertia is None or not finite(*ine.inertia):
        return None
    J = inr.tensor(*ine.inertia)
    moments = inr.principal_moments(J)
    vals = dict(zip(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), ine.inertia, strict=True))
    if all(x == 0.0 for x in ine.inertia):
        return None  # a point mass: fine on its own; check/bodies.py checks what joints move
    noise = max(MIN_MOMENT, ZERO_RTOL * float(ine.mass or 0.0) * _size(link) ** 2)
    if max(abs(moments[0]), abs(moments[-1])) <= noise:
        out.add(
            "inertia-not-pd",
            ine.inertia_line,
            f"link {link.name!r}: inertia is rounding noise, principal moments {_fmt(moments)} "
            f"all within {noise:.3g} kg m² of zero for mass {ine.mass:g} kg; MuJoCo rejects a "
            "non-zero tensor without positive eigenvalues: write the part's inertia"
            + _fix_suffix(fix := _solid_fix(link, ine)),
            fix,
            link=link.name,
            principal=[float(x) for x in moments],
            **vals,
        )
        return None
    if moments[0] <= MIN_MOMENT:
        out.add(
            "inertia-not-pd",
            ine.inertia_line,
            f"link {link.name!r}: inertia not positive definite, principal moments "
            f"{_fmt(moments)} for mass {ine.mass:g} kg" + _fix_suffix(fix := _solid_fix(link, ine)),
            fix,
            link=link.name,
            principal=[float(x) for x in moments],
            **vals,
        )
        return None
    excess = inr.triangle_violation(J)
    if excess > inr.TRIANGLE_RTOL:
        a, b, c = moments
        out.add(
            "inertia-triangle",
            ine.inertia_line,
            f"link {link.name!r}: principal moments {_fmt(moments)}: "
            f"{c:.4g} > {a:.4g} + {b:.4g} (by {excess:.1%})"
            + _fix_suffix(fix := _solid_fix(link, ine)),
            fix,
            link=link.name,
            principal=[float(x) for x in moments],
            excess=excess,
        )
        return None
    return J


def primitive_shape(link: Link) -> Shape | None:
    """The one box/cylinder/sphere the link is made of, or None.

    Every visual and collision element must be that same primitive at the same
    origin: a primitive collision next to a mesh visual is only an approximation
    of the body, and its formula says nothing about the real inertia.
    """
    shapes = (*link.collisions, *link.visuals)
    if not shapes:
        return None
    first = shapes[0]
    g = first.geometry
    if g is None or g.kind not in ("box", "cylinder", "sphere") or g.dims is None:
        return None
    if not all(d > 0 for d in g.dims):
        return None
    same = all(
        s.geometry is not None
        and (s.geometry.kind, s.geometry.dims) == (g.kind, g.dims)
        and (s.origin.xyz, s.origin.rpy) == (first.origin.xyz, first.origin.rpy)
        for s in shapes
    )
    return first if same else None


def _size(link: Link) -> float:
    """The link's size L [m] for ZERO_RTOL.

    Its largest primitive dimension (a diameter for spheres and cylinders), else the
    distance of its centre of mass from the link origin.
    """
    sizes = [
        max((2.0 * g.dims[0], *g.dims[1:])) if g.kind in ("sphere", "cylinder") else max(g.dims)
        for s in (*link.collisions, *link.visuals)
        if (g := s.geometry) is not None and g.dims and finite(*g.dims)
    ]
    if sizes:
        return max(sizes)
    ine = link.inertial
    xyz = ine.origin.xyz if ine is not None and finite(*ine.origin.xyz) else (0.0, 0.0, 0.0)
    return float(np.linalg.norm(xyz))


def _solid_fix(link: Link, ine: Inertial) -> dict[str, float]:
    """The solid-body inertia of the link's one primitive, in its inertial frame, or {}."""
    shape = primitive_shape(link)
    if shape is None or shape.geometry is None or not finite(ine.mass) or (ine.mass or 0) <= 0:
        return {}
    if not finite(*ine.origin.rpy, *shape.origin.rpy):
        return {}
    R_geom_inertial = rpy_matrix(shape.origin.rpy).T @ rpy_matrix(ine.origin.rpy)
    return bounds.fix_values(
        bounds.solid_inertia(shape.geometry, float(ine.mass or 0.0)), R_geom_inertial
    )


def _fix_suffix(fix: dict[str, float]) -> str:
    return f"; the solid shape's inertia would be {bounds.fix_text(fix)}" if fix else ""


def _versus_geometry(link: Link, ine: Inertial, J: np.ndarray, out: Collector) -> None:
    exceeded = _exceeds(link, ine, J, out)
    shape = primitive_shape(link)
    if shape is None or shape.geometry is None:
        return
    poses = (*ine.origin.xyz, *ine.origin.rpy, *shape.origin.xyz, *shape.origin.rpy)
    if not finite(*poses):
        return  # reported by the number rules
    g, m = shape.geometry, float(ine.mass or 0.0)
    R_link_geom = rpy_matrix(shape.origin.rpy)
    R_link_inertial = rpy_matrix(ine.origin.rpy)
    # Both tensors expressed in the geometry frame, where the formula is diagonal.
    actual = inr.rotate(inr.rotate(J, R_link_inertial), R_link_geom.T)
    expected = bounds.solid_inertia(g, m)
    diff = inr.relative_difference(actual, expected)
    dims = "x".join(f"{x:g}" for x in g.dims or ())
    if diff > INERTIA_GEOMETRY_RTOL and not exceeded:
        got, want = np.diag(actual), np.diag(expected)
        fix = bounds.fix_values(expected, R_link_geom.T @ R_link_inertial)
        out.add(
            "inertia-geometry",
            ine.inertia_line,
            f"link {link.name!r}: inertia diag "
            f"{_fmt(got)} (geometry frame) vs solid {g.kind} {dims} m, {m:g} kg: "
            f"{_fmt(want)}{_diagnosis(got, want)}{_fix_suffix(fix)}",
            fix,
            link=link.name,
            actual=_list(got),
            expected=_list(want),
            relative_difference=diff,
        )
    offset = np.subtract(ine.origin.xyz, shape.origin.xyz)
    tol = COM_ATOL + COM_RTOL * max(g.dims or (0.0,))
    if float(np.linalg.norm(offset)) > tol:
        out.add(
            "com-geometry",
            ine.origin.line or ine.line,
            f"link {link.name!r}: inertial "
            f"origin {list(ine.origin.xyz)} is {np.linalg.norm(offset):.4g} m from the "
            f"{g.kind} centre {list(shape.origin.xyz)}",
            link=link.name,
            offset=_list(offset),
        )


def _exceeds(link: Link, ine: Inertial, J: np.ndarray, out: Collector) -> bool:
    """`inertia-exceeds-geometry` for a link made of one primitive; True if it fired.

    `inertia-exceeds-visual` (a warning) when the primitive is a visual without collision.

    Every visual and collision element must be that primitive (primitive_shape): a box
    collision next to a mesh visual is a simplification of a body that may reach beyond it
    (example-robot-data's a1 and go1 legs: 165 false errors with the collision alone).
    """
    shape = primitive_shape(link)
    if shape is None or shape.geometry is None:
        return False
    if not finite(*ine.origin.xyz, *ine.origin.rpy, *shape.origin.xyz, *shape.origin.rpy):
        return False  # reported by the number rules
    g, m = shape.geometry, float(ine.mass or 0.0)
    R_link_geom = rpy_matrix(shape.origin.rpy)
    R_geom_inertial = R_link_geom.T @ rpy_matrix(ine.origin.rpy)
    offset = R_link_geom.T @ np.subtract(ine.origin.xyz, shape.origin.xyz)
    ex = bounds.excess(inr.rotate(J, R_geom_inertial), m, offset, g)
    if not ex.axes:
        return False
    k = [bounds.AXES.index(a) for a in ex.axes]
    fix = bounds.fix_values(bounds.solid_inertia(g, m), R_geom_inertial)
    dims = "x".join(f"{x:g}" for x in g.dims or ())
    moments = ", ".join(
        f"{a}: {ex.centre[i]:.4g} > {ex.bound[i]:.4g}" for a, i in zip(ex.axes, k, strict=True)
    )
    solid = np.asarray(ex.solid)
    # A shape the simulator collides with is the body; a visual-only one may be a picture
    # (Go1's rotor discs, whose collisions the file comments out): weaker evidence.
    out.add(
        "inertia-exceeds-geometry" if link.collisions else "inertia-exceeds-visual",
        ine.inertia_line,
        f"link {link.name!r}: moments about its {g.kind} {dims} m centre ({moments}) exceed "
        f"the most {m:g} kg inside that {_role(link)} shape can have (all mass on its extremes); "
        f"solid {g.kind}: {_fmt(solid)} "
        f"(geometry frame){_diagnosis(np.diag(inr.rotate(J, R_geom_inertial)), solid)}"
        f"{_fix_suffix(fix)}",
        fix,
        link=link.name,
        axes=", ".join(ex.axes),
        about_centre=list(ex.centre),
        bound=list(ex.bound),
        solid=list(ex.solid),
    )
    return True


def _role(link: Link) -> str:
    """Which elements the link's one primitive stands for: both, collision or visual."""
    if link.collisions and link.visuals:
        return "visual and collision"
    return "collision" if link.collisions else "visual"


def _diagnosis(got: np.ndarray, want: np.ndarray) -> str:
    """Name the usual macro bugs: a uniform scale factor and/or permuted axes."""
    for perm in itertools.permutations(range(3)):
        ratio = got / want[list(perm)]
        if np.ptp(ratio) <= INERTIA_GEOMETRY_RTOL * np.mean(ratio):
            scale = float(np.mean(ratio))
            parts = []
            if perm != (0, 1, 2):
                parts.append("axes permuted")
            if abs(scale - 1.0) > INERTIA_GEOMETRY_RTOL:
                parts.append(
                    f"{scale:.3g}x too large" if scale > 1 else f"{1 / scale:.3g}x too small"
                )
            return " (" + ", ".join(parts) + ")" if parts else ""
    return ""


def _fmt(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in v) + ")"


def _list(v: np.ndarray) -> list[float]:
    return [float(x) for x in v]
