"""The floor plan a base path is planned on: the robot's and the objects' outlines from above.

Conservative, so that a path free here is free for the 3-D collision checker that certifies
it: the robot's outline is the convex hull of its collision shapes' bounding boxes (arm in
its travel configuration) from above, an object's that of each primitive's points
(`plan.mobile.objects`), and an object counts when its height range meets the robot's
(a table top above the robot does not block it). Convex polygons are (N, 2) arrays,
counter-clockwise; overlap is the separating-axis test.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from armcli.analysis.support import convex_hull
from armcli.plan.mobile.objects import _points, world_objects
from armcli.plan.mobile.virtual import MobileRobot
from armcli.robot.collision import box_corners


@dataclass(frozen=True)
class Outline:
    """A convex outline from above [m], with its bounding circle for a quick test."""

    points: np.ndarray  # (N, 2) counter-clockwise
    centre: np.ndarray  # (2,)
    radius: float
    name: str = ""


def outline(points: np.ndarray, name: str = "") -> Outline:
    """The convex hull of points (K, 2) as an Outline."""
    hull = np.array(convex_hull([(float(x), float(y)) for x, y in points]), dtype=float)
    centre = hull.mean(axis=0)
    return Outline(hull, centre, float(np.max(np.linalg.norm(hull - centre, axis=1))), name)


def robot_outline(
    mobile: MobileRobot, q: np.ndarray, origin: np.ndarray | None = None
) -> tuple[Outline, float]:
    """The robot's outline with the arm at q, and its top [m].

    In the base frame, or about `origin` (x, y in the base frame: the point it turns about).
    """
    robot = mobile.robot
    q_robot = robot.q(mobile.x((0.0, 0.0, 0.0), q))
    corners = [box for _, box in box_corners(robot.robot, robot.geometry, q_robot)]
    pts = np.concatenate(corners)
    shift = np.zeros(2) if origin is None else np.asarray(origin, dtype=float)
    return outline(pts[:, :2] - shift, "robot"), float(pts[:, 2].max())


def obstacles(mobile: MobileRobot, top: float) -> list[Outline]:
    """Each world object's primitives whose height range meets [0, top], from above."""
    out = []
    for obj in world_objects(mobile.scene):
        for shape in obj.shapes:
            pts = _points(shape)
            if pts[:, 2].min() < top and pts[:, 2].max() > 0.0:
                out.append(outline(pts[:, :2], obj.id))
    return out


def placed(shape: Outline, x: float, y: float, yaw: float) -> np.ndarray:
    """The outline's points turned by yaw and moved to (x, y)."""
    c, s = math.cos(yaw), math.sin(yaw)
    R = np.array([[c, -s], [s, c]])
    return np.asarray(shape.points @ R.T + np.array([x, y]))


def grown(shape: Outline, d: float) -> Outline:
    """The outline pushed out by d [m] on every side: a polygon around its rounded offset."""
    p = shape.points
    e = np.roll(p, -1, axis=0) - p
    n = np.stack([e[:, 1], -e[:, 0]], axis=1) / np.linalg.norm(e, axis=1, keepdims=True)
    prev = np.roll(n, 1, axis=0)
    bis = n + prev
    scale = d / np.maximum(np.einsum("ij,ij->i", bis, n), 1e-9)
    pts = p + bis * scale[:, None]
    return Outline(
        pts,
        shape.centre,
        shape.radius + float(np.max(np.linalg.norm(bis * scale[:, None], axis=1))),
        shape.name,
    )


class Outlines:
    """Many convex outlines stacked, tested against one polygon at a time (vectorised SAT)."""

    def __init__(self, shapes: list[Outline]) -> None:
        """Stack the shapes' points, edge normals and offsets."""
        self.shapes = shapes
        pts = [o.points for o in shapes] or [np.zeros((0, 2))]
        self.v = np.concatenate(pts)
        self.start = np.cumsum([0] + [len(p) for p in pts[:-1]]).astype(np.intp)
        e = np.concatenate([np.roll(p, -1, axis=0) - p for p in pts])
        self.n = np.stack([e[:, 1], -e[:, 0]], axis=1)  # outward (counter-clockwise)
        self.c = np.einsum("ij,ij->i", self.v, self.n)
        self.e = e
        self.lo = np.array([o.points.min(axis=0) for o in shapes]).reshape(-1, 2)
        self.hi = np.array([o.points.max(axis=0) for o in shapes]).reshape(-1, 2)

    def meets(self, poly: np.ndarray) -> bool:
        """Whether a convex polygon (counter-clockwise) overlaps any outline.

        Outlines whose bounding box misses the polygon's are passed over first (most poses
        are far from most objects); the separating-axis test runs on the rest at once.
        """
        if not self.shapes:
            return False
        lo, hi = poly.min(axis=0), poly.max(axis=0)
        near = np.nonzero(np.all((self.lo < hi) & (self.hi > lo), axis=1))[0]
        if len(near) == 0:
            return False
        if len(near) < len(self.shapes):
            return Outlines([self.shapes[k] for k in near]).meets(poly)
        own = np.roll(poly, -1, axis=0) - poly
        n = np.stack([own[:, 1], -own[:, 0]], axis=1)
        c = np.einsum("ij,ij->i", poly, n)
        apart = np.logical_or.reduceat(np.min(poly @ self.n.T, axis=0) >= self.c, self.start)
        theirs = np.minimum.reduceat(self.v @ n.T, self.start, axis=0)  # (shapes, own edges)
        apart |= np.any(theirs >= c, axis=1)
        return not bool(np.all(apart))

    def distance(self, p: np.ndarray) -> float:
        """The least distance [m] from a point to the outlines (0 inside one)."""
        if not self.shapes:
            return math.inf
        t = np.clip(
            np.einsum("ij,ij->i", p - self.v, self.e) / np.einsum("ij,ij->i", self.e, self.e),
            0.0,
            1.0,
        )
        d = np.linalg.norm(self.v + t[:, None] * self.e - p, axis=1)
        left = self.e[:, 0] * (p[1] - self.v[:, 1]) - self.e[:, 1] * (p[0] - self.v[:, 0]) >= 0
        if np.any(np.logical_and.reduceat(left, self.start)):
            return 0.0
        return float(np.min(d))


def overlap(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two convex polygons (counter-clockwise) overlap (touching does not count)."""
    for p, q in ((a, b), (b, a)):
        e = np.roll(p, -1, axis=0) - p
        n = np.stack([e[:, 1], -e[:, 0]], axis=1)  # outward normals
        if np.any(np.min(q @ n.T, axis=0) >= np.einsum("ij,ij->i", p, n)):
            return False
    return True


def sweep(shape: Outline, a: np.ndarray, b: np.ndarray, yaw: float) -> np.ndarray:
    """The area the outline covers translating from a to b at a fixed yaw (a convex hull)."""
    pts = np.concatenate([placed(shape, a[0], a[1], yaw), placed(shape, b[0], b[1], yaw)])
    return np.array(convex_hull([(float(x), float(y)) for x, y in pts]), dtype=float)
