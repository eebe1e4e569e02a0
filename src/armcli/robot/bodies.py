"""Rigid bodies lumped across fixed joints: the one place links are merged into bodies.

A body is a movable joint's child link plus everything fixed to it, directly or in a
chain (Pinocchio's URDF parser, MuJoCo's `fusestatic`, Gazebo's fixed-joint reduction).
Its mass is the sum of its links', its centre of mass their mass-weighted mean and its
inertia about that centre the sum of theirs moved there (Steiner). `check` judges the
lumped bodies (a moving body needs mass and a regular inertia); `export mjcf` merges the
inertials MuJoCo refuses into their rigid neighbours with the same operations.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from armcli.robot import inertia as inr
from armcli.robot.frames import rpy_matrix
from armcli.urdf.doc import Joint, Link, Vec3


@dataclass(frozen=True)
class Mass:
    """Mass [kg], centre of mass [m] and the tensor about it [kg·m²], in one frame."""

    mass: float
    com: np.ndarray  # (3,)
    J: np.ndarray  # (3, 3)


def link_mass(link: Link) -> Mass | None:
    """The link's inertial in its own frame, or None when it has none or zero mass."""
    ine = link.inertial
    if ine is None or ine.mass is None or ine.inertia is None or ine.mass == 0.0:
        return None
    J = inr.tensor(*ine.inertia)
    if any(ine.origin.rpy):
        J = inr.rotate(J, rpy_matrix(ine.origin.rpy))
    return Mass(float(ine.mass), np.asarray(ine.origin.xyz, dtype=float), J)


def combine(parts: Sequence[Mass]) -> Mass:
    """The composite of rigidly joined inertials given in one frame (at least one).

    A composite without mass has its centre of mass at the frame's origin.
    """
    total = float(sum(p.mass for p in parts))
    com = sum((p.mass * p.com for p in parts), np.zeros(3)) / total if total > 0 else np.zeros(3)
    J = np.zeros((3, 3))
    for p in parts:
        J += inr.parallel_axis(p.J, p.mass, tuple(p.com - com))
    return Mass(total, com, J)


def join(a: Mass | None, b: Mass | None) -> Mass | None:
    """Two rigidly joined inertials in one frame as one; either may be absent."""
    if a is None or b is None:
        return a if b is None else b
    return combine([a, b])


def moved(x: Mass, xyz: Vec3, rpy: Vec3, *, inverse: bool = False) -> Mass:
    """`x` expressed in the parent's frame (or, inverse, from the parent's into the child's).

    `xyz`, `rpy`: the child frame's placement in the parent's [m, rad], as a URDF origin.
    """
    R, p = rpy_matrix(rpy), np.asarray(xyz, dtype=float)
    if inverse:
        return Mass(x.mass, R.T @ (x.com - p), inr.rotate(x.J, R.T))
    return Mass(x.mass, p + R @ x.com, inr.rotate(x.J, R))


@dataclass(frozen=True)
class Body:
    """A lumped rigid body in the frame of the link its joint moves."""

    joint: str
    link: str
    links: tuple[str, ...]
    mass: float  # [kg]
    com: np.ndarray  # [m], in the joint child link's frame
    inertia: np.ndarray  # [kg·m²] about com, in the same frame
    unknown: bool = False  # some part has unusable numbers (not lumped; reported elsewhere)


def rigid_group(
    links: Mapping[str, Link], root: str, joints: Iterable[Joint]
) -> list[tuple[Link, np.ndarray, np.ndarray]]:
    """`root` and every link fixed to it, each with its rotation and origin in root's frame.

    `joints`: one parent joint per child link (a tree); the root comes first.
    """
    fixed = [j for j in joints if j.type == "fixed" and j.child in links]
    parts = [(links[root], np.eye(3), np.zeros(3))]
    frontier = [parts[0]]
    while frontier:
        link, R, p = frontier.pop()
        for j in fixed:
            if j.parent == link.name:
                Rj, pj = rpy_matrix(j.origin.rpy), np.asarray(j.origin.xyz, dtype=float)
                item = (links[str(j.child)], R @ Rj, p + R @ pj)
                parts.append(item)
                frontier.append(item)
    return parts


def lump(links: Mapping[str, Link], joint: Joint, joints: Iterable[Joint]) -> Body:
    """`joint`'s child link lumped with every link fixed to it (see `rigid_group`).

    A negative mass counts as none; a link with a non-finite number is left out and the
    body marked `unknown`.
    """
    parts = rigid_group(links, str(joint.child), joints)
    masses: list[Mass] = []
    unknown = False
    for link, R, p in parts:
        ine = link.inertial
        if ine is None:
            continue
        if not _finite_inertial(link) or not np.all(np.isfinite(p)) or not np.all(np.isfinite(R)):
            unknown = True
            continue
        assert ine.inertia is not None and ine.mass is not None  # _finite_inertial
        Ri = R @ rpy_matrix(ine.origin.rpy)
        com = p + R @ np.asarray(ine.origin.xyz, dtype=float)
        masses.append(
            Mass(max(float(ine.mass), 0.0), com, inr.rotate(inr.tensor(*ine.inertia), Ri))
        )
    body = combine(masses) if masses else Mass(0.0, np.zeros(3), np.zeros((3, 3)))
    names = tuple(lk.name for lk, _, _ in parts)
    return Body(joint.name, str(joint.child), names, body.mass, body.com, body.J, unknown)


def _finite_inertial(link: Link) -> bool:
    ine = link.inertial
    if ine is None or ine.mass is None or ine.inertia is None:
        return False
    numbers = (ine.mass, *ine.inertia, *ine.origin.xyz, *ine.origin.rpy)
    return all(math.isfinite(x) for x in numbers)
