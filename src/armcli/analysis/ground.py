"""Where a robot touches the ground: the lowest points of its collision geometry.

At the neutral pose (every joint at zero) each link's collision shapes are placed by
Pinocchio's forward kinematics in the root link's frame; the ground plane is the lowest
point of all of them, and a link touches it when its own lowest point is within a
tolerance of that plane (rigid bodies on flat ground, the root frame upright): 2 % of the
robot's footprint (the larger horizontal extent of the lowest points within 5 mm of the
plane), at least 5 mm and at most 10 mm. Real bases are not exact at the zero pose:
LoCoBot's wheels sit 2.45 mm above its caster and a Dingo's 2.24 mm, both resting on a
spring or tyre that gives that much. A user may name the contact links instead
(`--contact-links`).

Contact points. A rolling link (a wheel: the child of a revolute or continuous joint
whose axis is horizontal) touches the ground at one point, the middle of its tread below
the axle: the point the diff-drive model rolls on and the conservative choice for a
tyre, whose edges carry load only once it deforms. Any other contact link (a caster
ball, a foot, a skid) touches at all of its lowest points within the tolerance (a box
standing on the ground: its four bottom corners).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from armcli.robot.frames import link_frame, pose_matrix
from armcli.robot.model import Robot
from armcli.spec.joint_types import ROTARY_TYPES
from armcli.urdf.doc import Shape, Urdf, Vec3
from armcli.urdf.mesh_points import read_vertices
from armcli.urdf.meshes import MeshSearch, mesh_paths
from armcli.urdf.tree import KinematicTree

CONTACT_TOL = 0.005  # [m] a link within this of the lowest point touches the ground, at least
CONTACT_RTOL = 0.02  # of the robot's footprint: a 0.35 m base takes links within 7 mm
CONTACT_MAX_TOL = 0.01  # [m] at most: a base's underside 49 mm up is not on the ground (Tiago)
HORIZONTAL_TOL = 0.1  # |axis_z| below this: a wheel's axle (about 6 deg from level)
CIRCLE_POINTS = 32  # an upright cylinder's bottom rim: within 0.5 % of its radius

MeshVertices = Callable[[str, Vec3], NDArray[np.float64] | None]  # (uri, scale) -> (n, 3)


@dataclass(frozen=True)
class Contact:
    """A link touching the ground, its contact points [m] in the root frame."""

    link: str
    points: tuple[Vec3, ...]
    rolling: bool  # a wheel: one point below its axle


@dataclass(frozen=True)
class Ground:
    """The ground plane's height in the root frame [m] and the links that touch it."""

    height: float
    contacts: tuple[Contact, ...]
    declared: bool = False  # the contact links were named by the user
    tol: float = CONTACT_TOL  # [m] links whose lowest point is this close to the plane touch

    def points(self) -> list[Vec3]:
        """Every contact point [m] in the root frame."""
        return [p for c in self.contacts for p in c.points]

    @property
    def links(self) -> tuple[str, ...]:
        """The contact links, in file order."""
        return tuple(c.link for c in self.contacts)


def shape_points(shape: Shape, T: NDArray[np.float64], mesh: MeshVertices | None) -> NDArray[Any]:
    """Points [m] in the root frame among which a shape's lowest ones are (n, 3).

    `T` is the 4x4 pose of the shape's link in the root frame. A box gives its corners, a
    sphere its bottom, a cylinder the lowest point of each rim (the whole rim sampled
    when it stands upright), a mesh its vertices. Unknown shapes or an unreadable mesh
    give no point.
    """
    g = shape.geometry
    if g is None or (g.kind != "mesh" and not g.dims):
        return np.empty((0, 3))
    Tm = T @ pose_matrix(shape.origin.xyz, shape.origin.rpy)
    R, c = Tm[:3, :3], Tm[:3, 3]
    if g.kind == "box" and g.dims is not None and len(g.dims) == 3:
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        out: NDArray[Any] = c + (signs * (0.5 * np.array(g.dims))) @ R.T
        return out
    if g.kind == "sphere" and g.dims is not None:
        return np.array([c - np.array([0.0, 0.0, g.dims[0]])])
    if g.kind == "cylinder" and g.dims is not None and len(g.dims) == 2:
        return _cylinder_bottom(R, c, g.dims[0], g.dims[1])
    if g.kind == "mesh" and mesh is not None and g.filename:
        v = mesh(g.filename, g.scale)
        if v is not None and len(v):
            scaled: NDArray[Any] = c + v @ R.T
            return scaled
    return np.empty((0, 3))


def _cylinder_bottom(R: NDArray[Any], c: NDArray[Any], r: float, length: float) -> NDArray[Any]:
    a = R[:, 2]
    down = np.array([0.0, 0.0, -1.0])
    d = down - np.dot(down, a) * a  # steepest descent on the rim plane
    caps = (c + 0.5 * length * a, c - 0.5 * length * a)
    if np.linalg.norm(d) > 1e-9:
        d = d / np.linalg.norm(d)
        return np.array([cap + r * d for cap in caps])
    t = np.linspace(0.0, 2.0 * math.pi, CIRCLE_POINTS, endpoint=False)
    rim = r * (np.outer(np.cos(t), R[:, 0]) + np.outer(np.sin(t), R[:, 1]))
    return np.vstack([cap + rim for cap in caps])


def link_poses(robot: Robot, names: Collection[str]) -> dict[str, NDArray[np.float64]]:
    """4x4 pose [m] in the root frame of each named link at the neutral pose (Pinocchio FK)."""
    q = robot.neutral()
    found = {name: link_frame(robot.model, name) for name in names}
    return {name: robot.frame_pose(fid, q) for name, fid in found.items() if fid is not None}


def _rolling_links(urdf: Urdf, poses: dict[str, NDArray[np.float64]]) -> set[str]:
    """Links turned by a revolute or continuous joint about a horizontal axis (wheels).

    The joint's parent must be the base: joined to the root by fixed or prismatic joints
    only (a prismatic joint is a suspension or a wheel drop, as on LoCoBot's Create 3: it
    moves the axle without turning it). A wrist that hangs below a bolted arm's base at
    the neutral pose (example-robot-data's UR5) turns about a horizontal axis too, but
    behind rotary joints: it is not a wheel.
    """
    by_child = KinematicTree.of(urdf).parent_joint

    def on_base(link: str | None) -> bool:
        seen: set[str] = set()
        while link is not None and link in by_child and link not in seen:
            seen.add(link)
            up = by_child[link]
            if up.type not in ("fixed", "prismatic"):
                return False
            link = up.parent
        return True

    out = set()
    for j in urdf.joints:
        if j.type in ROTARY_TYPES and j.child in poses and j.axis is not None and on_base(j.parent):
            axis = poses[j.child][:3, :3] @ np.asarray(j.axis, dtype=float)
            n = float(np.linalg.norm(axis))
            if n > 0 and abs(axis[2]) / n < HORIZONTAL_TOL:
                out.add(j.child)
    return out


def find_ground(
    urdf: Urdf,
    robot: Robot,
    *,
    candidates: Collection[str] | None = None,
    declared: Sequence[str] | None = None,
    mesh: MeshVertices | None = None,
    tol: float | None = None,
) -> Ground | None:
    """The ground contacts at the neutral pose; None when no link has collision geometry.

    `candidates` limits which links may touch (a spec's mobile base); `declared` names the
    contact links outright: each then touches at its own lowest points. Links missing from
    the model are ignored; `declared` names are checked by the caller. `tol` [m]: by
    default `contact_tol` of the robot's collision geometry.
    """
    wanted = list(declared) if declared is not None else None
    pool = [lk for lk in urdf.links if lk.collisions]
    if wanted is not None:
        pool = [lk for lk in pool if lk.name in wanted]
    elif candidates is not None:
        pool = [lk for lk in pool if lk.name in candidates]
    poses = link_poses(robot, [lk.name for lk in pool])
    lowest: dict[str, NDArray[Any]] = {}
    for lk in pool:
        if lk.name not in poses:
            continue
        pts = [shape_points(s, poses[lk.name], mesh) for s in lk.collisions]
        pts = [p for p in pts if len(p)]
        if pts:
            lowest[lk.name] = np.vstack(pts)
    if not lowest:
        return None
    floor = min(float(p[:, 2].min()) for p in lowest.values())
    if tol is None:
        near = np.vstack([c[c[:, 2] <= floor + CONTACT_TOL] for c in lowest.values()])
        tol = contact_tol(near)
    rolling = _rolling_links(urdf, poses)
    contacts = []
    for name, cloud in lowest.items():
        own = float(cloud[:, 2].min())
        if wanted is None and own > floor + tol:
            continue
        low = cloud[cloud[:, 2] <= own + tol]
        if name in rolling:
            mid = low.mean(axis=0)
            chosen: list[Vec3] = [(float(mid[0]), float(mid[1]), own)]
        else:
            chosen = [(float(p[0]), float(p[1]), float(p[2])) for p in low]
        contacts.append(Contact(name, tuple(chosen), name in rolling))
    return Ground(floor, tuple(contacts), declared=wanted is not None, tol=tol)


def contact_tol(points: NDArray[Any]) -> float:
    """The contact tolerance [m] for a robot whose lowest points are these (n, 3).

    CONTACT_RTOL of the footprint (the larger of their x and y extents), within
    CONTACT_TOL..CONTACT_MAX_TOL. The points are those near the floor, not the whole robot:
    a dual-arm Tiago's arms span 2.5 m at the zero pose, its base 0.5 m.
    """
    extent = np.ptp(points[:, :2], axis=0) if len(points) else np.zeros(2)
    return min(CONTACT_MAX_TOL, max(CONTACT_TOL, CONTACT_RTOL * float(np.max(extent))))


def has_wheels(ground: Ground | None) -> bool:
    """Whether a rolling link touches the ground: a mobile base rather than a bolted arm."""
    return ground is not None and any(c.rolling for c in ground.contacts)


def mesh_loader(urdf: Urdf, search: MeshSearch, missing: list[str]) -> MeshVertices:
    """Vertices [m] of the URDF's meshes, read once each, scaled; confined like every mesh.

    A mesh that cannot be found, lies outside the allowed roots or cannot be read gives
    no points and its URI is appended to `missing` (the caller says so).
    """
    paths = mesh_paths(urdf, search)
    cache: dict[str, NDArray[np.float64] | None] = {}

    def vertices(uri: str, scale: Vec3) -> NDArray[np.float64] | None:
        if uri not in cache:
            cache[uri] = read_vertices(paths.get(uri), urdf.source)
            if cache[uri] is None:
                missing.append(uri)
        v = cache[uri]
        return None if v is None else v * np.asarray(scale, dtype=float)

    return vertices
