"""An independent reference for base placement of the course robot (specs/my_robot.yaml).

Nothing here comes from armcli.plan: the arm's forward kinematics in closed form, its
nearest approach to a point by brute force over a 0.1-degree grid of both joints (a
KD-tree of the tool's in-plane positions), the robot's collision shapes written out from
the spec's numbers, collisions in numpy against axis-aligned boxes and upright cylinders
(the only shapes the test scenes use), the tip-over margin from the spec's masses.

Every verdict is one of FEASIBLE, INFEASIBLE or AMBIGUOUS: the reference's own
approximations (the joint grid, points sampled along the arm's axes) are bounded, and a
pose within those bounds of a boundary is AMBIGUOUS rather than guessed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

FEASIBLE, AMBIGUOUS, INFEASIBLE = 1, 0, -1
# specs/my_robot.yaml: the mount (0.15, 0, 0.2) on base_link, base_link 0.1 above
# base_footprint, the first joint 0.02 above arm_base_link; links 0.3, tool 0.3 along hand_link.
SHOULDER = np.array([0.15, 0.0, 0.32])
L1, L2, R_ARM = 0.3, 0.3, 0.02  # [m] forearm and hand lengths, their cylinders' radius
Q_STEP = math.radians(0.1)  # the brute-force joint grid
REACH_BAND = 1.0e-3  # [m] the grid's nearest point is at most this much farther (0.6 m x 0.1°)
SAMPLE = 0.005  # [m] points along the arm's axes; a distance is overestimated by <= SAMPLE / 2
TOUCH = 1e-4  # [m] closer than this to a boundary: AMBIGUOUS (exact contact)
FLOOR_TOP = -0.001  # [m] armcli's floor slab (plan.mobile.virtual) is this far below z = 0
# The base's collision shapes from above (x0, x1, y0, y1, z0, z1) [m] in base_footprint:
# base_link's box, the wheels (cylinders about y: their shadows), arm_base_link's box.
BASE_RECTS = np.array([
    [-0.30, 0.30, -0.20, 0.20, 0.10, 0.30],
    [-0.25, -0.05, 0.20, 0.25, 0.00, 0.20],
    [-0.25, -0.05, -0.25, -0.20, 0.00, 0.20],
    [0.10, 0.20, -0.05, 0.05, 0.30, 0.32],
])  # fmt: skip
CASTER = (0.2, 0.0, 0.05, 0.05)  # x, y, z, radius [m]
# Masses [kg] and where their centres sit with the arm stowed (spec's links, origins):
# base_link, two wheels, caster, arm_base_link; forearm and hand move (see `tip_margin`).
FIXED_MASSES = [(5.0, (0.0, 0.0, 0.2)), (1.0, (-0.15, 0.225, 0.1)), (1.0, (-0.15, -0.225, 0.1)),
                (0.5, (0.2, 0.0, 0.05)), (0.5, (0.15, 0.0, 0.31))]  # fmt: skip
SUPPORT = np.array([[-0.15, -0.225], [0.2, 0.0], [-0.15, 0.225]])  # wheel and caster contacts


@dataclass(frozen=True)
class Box:
    """An axis-aligned box [m]."""

    lo: np.ndarray
    hi: np.ndarray


@dataclass(frozen=True)
class Cylinder:
    """An upright cylinder [m]."""

    centre: np.ndarray
    radius: float
    half: float


def read_objects(path: Path | None) -> list[tuple[str, Box | Cylinder]]:
    """The scene's primitives (unrotated boxes and cylinders), read with plain YAML."""
    if path is None:
        return []
    data = yaml.safe_load(path.read_text())
    out: list[tuple[str, Box | Cylinder]] = []
    for obj in data["world"]["collision_objects"]:
        for prim, pose in zip(obj["primitives"], obj["primitive_poses"], strict=True):
            c = np.array([pose["position"][k] for k in "xyz"], dtype=float)
            d = prim["dimensions"]
            if prim["type"] == "box":
                out.append((obj["id"], Box(c - np.array(d) / 2, c + np.array(d) / 2)))
            else:
                out.append((obj["id"], Cylinder(c, float(d[1]), float(d[0]) / 2)))
    return out


def arm_points(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(elbow, tool) [m] in base_footprint at joint values q (N, 2): the closed form."""
    s1, c1 = np.sin(q[:, 0]), np.cos(q[:, 0])
    s12, c12 = np.sin(q[:, 0] + q[:, 1]), np.cos(q[:, 0] + q[:, 1])
    zero = np.zeros(len(q))
    elbow = SHOULDER + L1 * np.stack([s1, zero, c1], axis=1)
    return elbow, elbow + L2 * np.stack([s12, zero, c12], axis=1)


class Reference:
    """The brute-force judge of base poses for the course robot among `objects`."""

    def __init__(self, objects: list[tuple[str, Box | Cylinder]], tolerance: float) -> None:
        from scipy.spatial import cKDTree

        g = np.arange(0.0, math.pi / 2 + Q_STEP / 2, Q_STEP)
        self.q = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
        _, tool = arm_points(self.q)
        self.tree = cKDTree(np.stack([tool[:, 0], tool[:, 2]], axis=1))
        self.objects = objects
        self.tolerance = tolerance

    def nearest(self, t_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nearest configuration (N, 2) and distance (N,) [m] to base-frame points (N, 3)."""
        d, i = self.tree.query(np.stack([t_b[:, 0], t_b[:, 2]], axis=1))
        return self.q[i], np.hypot(d, t_b[:, 1])

    def classify(self, bases: np.ndarray, target: np.ndarray) -> np.ndarray:
        """FEASIBLE / AMBIGUOUS / INFEASIBLE for each base pose (N, 3)."""
        c, s = np.cos(bases[:, 2]), np.sin(bases[:, 2])
        dx, dy = target[0] - bases[:, 0], target[1] - bases[:, 1]
        t_b = np.stack([c * dx + s * dy, -s * dx + c * dy, np.full(len(bases), target[2])], 1)
        q, d = self.nearest(t_b)
        out = np.full(len(bases), AMBIGUOUS)
        out[d <= self.tolerance - REACH_BAND] = FEASIBLE
        out[d > self.tolerance + REACH_BAND] = INFEASIBLE
        near = out != INFEASIBLE  # collisions only where the tool comes near enough
        hit = np.full(len(bases), FEASIBLE)
        if np.any(near):
            hit[near] = self.collides(bases[near], q[near])
        out[(out == FEASIBLE) & (hit == AMBIGUOUS)] = AMBIGUOUS
        out[hit == INFEASIBLE] = INFEASIBLE
        out[tip_margin(q) <= TOUCH] = INFEASIBLE
        return out

    def collides(self, bases: np.ndarray, q: np.ndarray) -> np.ndarray:
        """INFEASIBLE (a collision), FEASIBLE (none) or AMBIGUOUS per pose."""
        verdict = np.full(len(bases), FEASIBLE)
        base_hit = self._base_hits(bases)
        outer, inner = self._arm_clearance(bases, q)
        verdict[(outer - SAMPLE / 2 <= R_ARM + TOUCH)] = AMBIGUOUS
        verdict[(inner <= R_ARM - TOUCH) | base_hit] = INFEASIBLE
        return verdict

    def _base_hits(self, bases: np.ndarray) -> np.ndarray:
        """Whether the base's shapes (shadows and heights) meet an object's, per pose."""
        hit = np.zeros(len(bases), dtype=bool)
        c, s = np.cos(bases[:, 2]), np.sin(bases[:, 2])
        for _, obj in self.objects:
            z0, z1 = (obj.lo[2], obj.hi[2]) if isinstance(obj, Box) else (
                obj.centre[2] - obj.half, obj.centre[2] + obj.half)  # fmt: skip
            for x0, x1, y0, y1, b0, b1 in BASE_RECTS:
                if z1 <= b0 or z0 >= b1:
                    continue
                hit |= _rect_meets(bases, c, s, (x0, x1, y0, y1), obj)
            cx, cy, cz, r = CASTER
            if z0 < cz + r and z1 > cz - r:
                px = bases[:, 0] + c * cx - s * cy
                py = bases[:, 1] + s * cx + c * cy
                hit |= _circle_meets(px, py, r, obj)
        return hit

    def _arm_clearance(self, bases: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Least distance [m] of the arm's axes (full, and shortened by R_ARM) to anything."""
        elbow, tool = arm_points(q)
        ends = [(SHOULDER[None, :].repeat(len(q), 0), elbow), (elbow, tool)]
        outer = np.full(len(bases), np.inf)
        inner = np.full(len(bases), np.inf)
        for a, b in ends:
            for shrink, best in ((0.0, outer), (R_ARM, inner)):
                pts = _world(bases, _along(a, b, shrink))
                for _, obj in self.objects:
                    np.minimum(best, np.min(_distance(pts, obj), axis=1), out=best)
                np.minimum(best, np.min(pts[..., 2] - FLOOR_TOP, axis=1), out=best)
        return outer, inner


def _along(a: np.ndarray, b: np.ndarray, shrink: float) -> np.ndarray:
    """Points (N, K, 3) every <= SAMPLE along the segments a -> b shortened by `shrink`."""
    d = b - a
    length = np.linalg.norm(d, axis=1, keepdims=True)
    u = d / length
    a2, b2 = a + shrink * u, b - shrink * u
    k = math.ceil(float(np.max(length)) / SAMPLE) + 1
    t = np.linspace(0.0, 1.0, k)[None, :, None]
    return np.asarray(a2[:, None, :] + t * (b2 - a2)[:, None, :])


def _world(bases: np.ndarray, pts: np.ndarray) -> np.ndarray:
    c, s = np.cos(bases[:, 2])[:, None], np.sin(bases[:, 2])[:, None]
    x = bases[:, 0:1] + c * pts[..., 0] - s * pts[..., 1]
    y = bases[:, 1:2] + s * pts[..., 0] + c * pts[..., 1]
    return np.stack([x, y, pts[..., 2]], axis=-1)


def _distance(pts: np.ndarray, obj: Box | Cylinder) -> np.ndarray:
    """Distance [m] from points (..., 3) to an object (0 inside)."""
    if isinstance(obj, Box):
        gap = np.maximum(np.maximum(obj.lo - pts, pts - obj.hi), 0.0)
        return np.asarray(np.linalg.norm(gap, axis=-1))
    radial = np.maximum(np.hypot(pts[..., 0] - obj.centre[0], pts[..., 1] - obj.centre[1])
                        - obj.radius, 0.0)  # fmt: skip
    axial = np.maximum(np.abs(pts[..., 2] - obj.centre[2]) - obj.half, 0.0)
    return np.asarray(np.hypot(radial, axial))


def _rect_meets(bases: np.ndarray, c: np.ndarray, s: np.ndarray, rect: tuple[float, ...],
                obj: Box | Cylinder) -> np.ndarray:  # fmt: skip
    """Whether a base rectangle (base frame) overlaps an object's shadow, per pose."""
    x0, x1, y0, y1 = rect
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    wx = bases[:, 0:1] + c[:, None] * corners[:, 0] - s[:, None] * corners[:, 1]
    wy = bases[:, 1:2] + s[:, None] * corners[:, 0] + c[:, None] * corners[:, 1]
    if isinstance(obj, Cylinder):  # the circle's centre in the rectangle's frame, clamped
        dx, dy = obj.centre[0] - bases[:, 0], obj.centre[1] - bases[:, 1]
        lx, ly = c * dx + s * dy, -s * dx + c * dy
        gx = np.maximum(np.maximum(x0 - lx, lx - x1), 0.0)
        gy = np.maximum(np.maximum(y0 - ly, ly - y1), 0.0)
        return np.asarray(np.hypot(gx, gy) < obj.radius)
    # separating axes: the box's two, the rectangle's two
    apart = (wx.max(1) <= obj.lo[0]) | (wx.min(1) >= obj.hi[0])
    apart |= (wy.max(1) <= obj.lo[1]) | (wy.min(1) >= obj.hi[1])
    box = np.array([[obj.lo[0], obj.lo[1]], [obj.hi[0], obj.lo[1]], [obj.hi[0], obj.hi[1]],
                    [obj.lo[0], obj.hi[1]]])  # fmt: skip
    for axis, (lo, hi) in ((0, (x0, x1)), (1, (y0, y1))):
        ux = np.where(axis == 0, c, -s)[:, None]
        uy = np.where(axis == 0, s, c)[:, None]
        proj = (box[None, :, 0] - bases[:, 0:1]) * ux + (box[None, :, 1] - bases[:, 1:2]) * uy
        apart |= (proj.max(1) <= lo) | (proj.min(1) >= hi)
    return np.asarray(~apart)


def _circle_meets(px: np.ndarray, py: np.ndarray, r: float, obj: Box | Cylinder) -> np.ndarray:
    if isinstance(obj, Cylinder):
        return np.asarray(np.hypot(px - obj.centre[0], py - obj.centre[1]) < r + obj.radius)
    gx = np.maximum(np.maximum(obj.lo[0] - px, px - obj.hi[0]), 0.0)
    gy = np.maximum(np.maximum(obj.lo[1] - py, py - obj.hi[1]), 0.0)
    return np.asarray(np.hypot(gx, gy) < r)


def tip_margin(q: np.ndarray) -> np.ndarray:
    """[m] the centre of mass's distance inside the wheel-caster triangle, per configuration."""
    s1, s12 = np.sin(q[:, 0]), np.sin(q[:, 0] + q[:, 1])
    m_total = sum(m for m, _ in FIXED_MASSES) + 0.6
    x = sum(m * p[0] for m, p in FIXED_MASSES) + 0.3 * (SHOULDER[0] + 0.15 * s1)
    x = x + 0.3 * (SHOULDER[0] + L1 * s1 + 0.15 * s12)
    y = np.zeros(len(q)) + sum(m * p[1] for m, p in FIXED_MASSES)
    com = np.stack([x / m_total, y / m_total], axis=1)
    margins = []
    for i in range(3):
        a, b = SUPPORT[i], SUPPORT[(i + 1) % 3]
        n = np.array([b[1] - a[1], a[0] - b[0]]) / np.hypot(*(b - a))  # outward: counter-clockwise
        margins.append(-((com - a) @ n))
    return np.min(np.stack(margins), axis=0)
