"""Rules on the rigid bodies the joints move, lumped as simulators lump them.

A body is a movable joint's child link plus everything fixed to it (Pinocchio,
MuJoCo's fusestatic, Gazebo's fixed-joint reduction).

A zero-mass frame link fixed to a heavy link is fine; what breaks the mass
matrix is a moving *body* with no mass or a singular inertia (a lone point
mass). This is also the condition MuJoCo's compiler enforces ("mass and inertia
of moving bodies must be larger than mjMINVAL"), which the corpus test uses as
an oracle.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from armcli.check.inertia import MIN_MOMENT
from armcli.check.rules import Collector
from armcli.check.structure import Tree, finite
from armcli.robot import inertia as inr
from armcli.urdf.doc import Joint, Link, Urdf

# A moving body lighter than this fraction of the robot makes the dynamics stiff.
TINY_MASS_RATIO = 1e-4
# A link-level finding of these rules already names the problem of the body it belongs to
# (negative mass is not reported again as "the body has no mass").
LINK_ERRORS = ("mass-nonpositive", "inertia-not-pd", "inertia-triangle")


@dataclass(frozen=True)
class Body:
    """A lumped rigid body in the frame of the link its joint moves."""

    joint: str
    link: str
    links: tuple[str, ...]
    mass: float  # [kg]
    com: np.ndarray  # [m], in the joint child link's frame
    inertia: np.ndarray  # [kg·m²] about com, in the same frame
    unknown: bool = False  # some part has unusable numbers (already reported)


def _transform(j: Joint) -> tuple[np.ndarray, np.ndarray]:
    return inr.rpy_matrix(j.origin.rpy), np.asarray(j.origin.xyz, dtype=float)


def lump(urdf: Urdf, tree: Tree, joint: Joint) -> Body:
    """Lump `joint`'s child link with every link fixed to it (directly or in a chain)."""
    links: dict[str, Link] = {}
    for lk in urdf.links:
        links.setdefault(lk.name, lk)  # a duplicate name is reported; the first one counts
    child = str(joint.child)
    parts: list[tuple[Link, np.ndarray, np.ndarray]] = [(links[child], np.eye(3), np.zeros(3))]
    frontier = [parts[0]]
    while frontier:
        link, R, p = frontier.pop()
        for j in tree.parent_joint.values():
            if j.parent == link.name and j.type == "fixed" and j.child in links:
                Rj, pj = _transform(j)
                item = (links[str(j.child)], R @ Rj, p + R @ pj)
                parts.append(item)
                frontier.append(item)
    masses, coms, tensors = [], [], []
    unknown = False
    for link, R, p in parts:
        ine = link.inertial
        if ine is None:
            continue
        if not _finite_inertial(link) or not np.all(np.isfinite(p)) or not np.all(np.isfinite(R)):
            unknown = True  # reported by the number rules; the body cannot be judged
            continue
        assert ine.inertia is not None  # _finite_inertial
        Ri = R @ inr.rpy_matrix(ine.origin.rpy)
        masses.append(max(float(ine.mass or 0.0), 0.0))
        coms.append(p + R @ np.asarray(ine.origin.xyz, dtype=float))
        tensors.append(inr.rotate(inr.tensor(*ine.inertia), Ri))
    total = float(sum(masses))
    com = (
        sum((m * c for m, c in zip(masses, coms, strict=True)), np.zeros(3)) / total
        if total > 0
        else np.zeros(3)
    )
    J = np.zeros((3, 3))
    for m, c, Jc in zip(masses, coms, tensors, strict=True):
        J += inr.parallel_axis(Jc, m, c - com)
    return Body(joint.name, child, tuple(lk.name for lk, _, _ in parts), total, com, J, unknown)


def _finite_inertial(link: Link) -> bool:
    ine = link.inertial
    return (
        ine is not None
        and finite(ine.mass)
        and ine.inertia is not None
        and finite(*ine.inertia, *ine.origin.xyz, *ine.origin.rpy)
    )


def _massless_consequences(urdf: Urdf, links: Sequence[str]) -> str:
    """What simulators make of a massless moving body, as measured with each.

    MuJoCo's URDF import gives a body whose links have no <inertial> at all a mass from
    its collision geometry (density 1000 kg/m³) and loads it; with an explicit zero mass,
    or nothing to take a mass from, it refuses ("mass and inertia of moving bodies must be
    larger than mjMINVAL").
    """
    found = [urdf.link(n) for n in links]
    parts = [lk for lk in found if lk is not None]
    no_inertial = all(lk.inertial is None for lk in parts)
    if no_inertial and any(lk.collisions for lk in parts):
        return (
            "no <inertial>; MuJoCo's URDF import loads it with a mass made up from its "
            "collision geometry at 1000 kg/m³, Gazebo drops or destabilises it"
        )
    return "MuJoCo refuses it (a moving body needs mass), Gazebo drops or destabilises it"


def moving_bodies(urdf: Urdf, tree: Tree) -> list[Body]:
    """One lumped body per movable joint whose child link exists, in document order."""
    names = {lk.name for lk in urdf.links}
    return [
        lump(urdf, tree, j)
        for j in urdf.joints
        if j.type != "fixed" and j.child in names and tree.parent_joint.get(str(j.child)) is j
    ]


def check(urdf: Urdf, tree: Tree, out: Collector) -> None:
    """Rules on moving bodies: no mass, a singular inertia, or a tiny share of the robot mass.

    Bodies with unusable numbers are skipped: the number rules already reported them.
    """
    total = _robot_mass(urdf)
    lines = {lk.name: lk.line for lk in urdf.links}
    for b in moving_bodies(urdf, tree):
        if b.unknown or any(out.has(LINK_ERRORS, link=name) for name in b.links):
            continue  # one finding per problem: the link's own finding explains the body
        where = f"the body moved by {b.joint!r} ({', '.join(b.links)})"
        if b.mass <= 0.0:
            out.add(
                "mass-nonpositive",
                lines.get(b.link),
                f"{where} has no mass: {_massless_consequences(urdf, b.links)}",
                joint=b.joint,
                link=b.link,
                mass=b.mass,
            )
            continue
        moments = inr.principal_moments(b.inertia)
        if moments[0] <= MIN_MOMENT:
            out.add(
                "inertia-not-pd",
                lines.get(b.link),
                f"{where} has a singular inertia, principal moments "
                f"{[float(f'{x:.4g}') for x in moments]} (e.g. a lone point mass)",
                joint=b.joint,
                link=b.link,
                principal=[float(x) for x in moments],
            )
        if total > 0 and b.mass < TINY_MASS_RATIO * total:
            out.add(
                "tiny-mass",
                lines.get(b.link),
                f"{where}: mass {b.mass:.3g} kg is "
                f"{b.mass / total:.1e} of the robot's {total:.4g} kg",
                joint=b.joint,
                link=b.link,
                mass=b.mass,
                robot_mass=total,
            )


def _robot_mass(urdf: Urdf) -> float:
    total = 0.0
    for lk in urdf.links:
        m = lk.inertial.mass if lk.inertial is not None else None
        if m is not None and finite(m) and m > 0:
            total += m
    return total
