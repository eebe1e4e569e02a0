"""The support polygon a robot stands on, and how far a point on the ground is inside it.

The polygon is the convex hull of the ground contact
points (`analysis.ground`), in the root link's x-y plane: rigid contacts on flat ground. A
point on the ground is statically balanced while it lies inside; its margin is the
distance to the nearest edge (negative outside: minus the distance to the polygon).
Each edge is a tipping axis; its outward normal names the direction the robot tips.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

COLLINEAR_TOL = 1e-6  # [m²] a hull of smaller area is a line or a point: no polygon
HULL_EPS = 1e-12  # [m²] cross products below this are collinear (rounding of the contact points)
# The eight compass directions of the root frame (+x forward, +y left, ROS REP 103).
_DIRECTIONS = (
    "front",
    "front-left",
    "left",
    "rear-left",
    "rear",
    "rear-right",
    "right",
    "front-right",
)


def direction_name(angle: float) -> str:
    """The compass name of a heading [rad] in the base frame: 0 is "front", pi/2 "left"."""
    k = round(angle / (math.pi / 4)) % 8
    return _DIRECTIONS[k]


@dataclass(frozen=True)
class Edge:
    """One side of the polygon: from `a` to `b` (counter-clockwise), outward unit `normal`.

    A point p is inside the edge's half-plane when normal · p <= offset.
    """

    a: tuple[float, float]
    b: tuple[float, float]
    normal: tuple[float, float]
    offset: float  # [m]

    @property
    def angle(self) -> float:
        """Heading of the outward normal [rad]: the direction the robot tips over this edge."""
        return math.atan2(self.normal[1], self.normal[0])

    @property
    def direction(self) -> str:
        """Compass name of that heading (`direction_name`)."""
        return direction_name(self.angle)


@dataclass(frozen=True)
class SupportPolygon:
    """Convex support polygon in the root x-y plane [m], vertices counter-clockwise."""

    vertices: tuple[tuple[float, float], ...]
    edges: tuple[Edge, ...]

    @functools.cached_property  # read at every state of a run's zero-moment-point series
    def normals(self) -> NDArray[np.float64]:
        """(k, 2) outward unit normals, one per edge."""
        return np.array([e.normal for e in self.edges], dtype=float)

    @functools.cached_property
    def offsets(self) -> NDArray[np.float64]:
        """(k,) edge offsets: normal · p <= offset inside."""
        return np.array([e.offset for e in self.edges], dtype=float)

    def edge_distances(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Signed distance [m] of a ground point to each edge's line (positive inside)."""
        p = np.asarray(xy, dtype=float)[:2]
        out: NDArray[np.float64] = self.offsets - self.normals @ p
        return out

    def margin(self, xy: ArrayLike) -> float:
        """Signed distance [m] to the polygon's boundary: positive inside, negative outside.

        Inside a convex polygon the nearest boundary point is on the nearest edge line;
        outside, the distance to the nearest point of the polygon (an edge or a corner).
        """
        nearest = float(self.edge_distances(xy).min())  # NaN (not finite): outside, below
        if nearest >= 0.0:
            return nearest
        p = np.asarray(xy, dtype=float)[:2]
        return -min(_segment_distance(p, e) for e in self.edges)

    def margins(self, points: ArrayLike) -> NDArray[np.float64]:
        """`margin` of each (m, 2) point at once; -inf for a point that is not finite."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        d = self.offsets[None, :] - p @ self.normals.T  # (m, k)
        a = np.array([e.a for e in self.edges], dtype=float)  # (k, 2)
        ab = np.array([e.b for e in self.edges], dtype=float) - a
        with np.errstate(invalid="ignore", divide="ignore"):
            u = np.clip(
                np.einsum("mkj,kj->mk", p[:, None, :] - a[None], ab) / np.sum(ab * ab, axis=1),
                0.0,
                1.0,
            )
        gap = np.linalg.norm(p[:, None, :] - (a[None] + u[..., None] * ab[None]), axis=2)
        out = np.where(np.all(d >= 0.0, axis=1), np.min(d, axis=1), -np.min(gap, axis=1))
        out[~np.all(np.isfinite(p), axis=1)] = -math.inf
        return np.asarray(out, dtype=float)

    def nearest_edge(self, xy: ArrayLike) -> int:
        """Index of the edge the point is nearest to inside (outside: the one it is beyond most)."""
        return int(np.argmin(self.edge_distances(xy)))

    @property
    def area(self) -> float:
        """The polygon's area [m²]."""
        v = np.array(self.vertices)
        x, y = v[:, 0], v[:, 1]
        return float(0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _segment_distance(p: NDArray[np.float64], e: Edge) -> float:
    a, b = np.array(e.a), np.array(e.b)
    ab = b - a
    t = float(np.clip(np.dot(p - a, ab) / max(float(np.dot(ab, ab)), 1e-300), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def support_polygon(points: Sequence[Sequence[float]]) -> SupportPolygon | None:
    """The convex hull of ground points (x, y[, z]) [m]; None when they span no area.

    Fewer than three points, or points on one line (a two-wheeled robot without its
    caster), give no polygon: such a robot balances on a line at best.
    """
    verts = convex_hull([(float(p[0]), float(p[1])) for p in points])
    if len(verts) < 3:
        return None
    v = np.array(verts)
    edges = []
    for i in range(len(v)):
        a, b = v[i], v[(i + 1) % len(v)]
        t = (b - a) / np.linalg.norm(b - a)
        n = np.array([t[1], -t[0]])  # right of a counter-clockwise edge: outward
        edges.append(Edge(_pt(a), _pt(b), _pt(n), float(n @ a)))
    polygon = SupportPolygon(tuple(verts), tuple(edges))
    return polygon if polygon.area >= COLLINEAR_TOL else None


def convex_hull(points: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """Vertices of the 2-D convex hull, counter-clockwise from the lowest-x point.

    Andrew's monotone chain: points on an edge are dropped. Written here rather than
    taken from scipy's ConvexHull (Qhull, the tests' reference) because importing
    scipy.spatial costs `check` about 0.5 s of CPU, more than the whole balance analysis.
    """
    pts = sorted(set(points))
    if len(pts) < 3:
        return pts

    def turn(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    upper: list[tuple[float, float]] = []
    for p in pts:
        while len(lower) >= 2 and turn(lower[-2], lower[-1], p) <= HULL_EPS:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and turn(upper[-2], upper[-1], p) <= HULL_EPS:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def _pt(v: NDArray[np.float64]) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))
