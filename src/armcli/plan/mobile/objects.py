"""The scene's objects seen from the floor: their outlines from above, what holds a point.

Placement names the object a target is inside, deeper than its tolerance (no base pose
can serve it: the tool would be in the object) without trying every pose, and the plot
draws each object's outline from above. Objects fixed to a robot link move with it and
are left out; so is a mesh for `containing` (inside a mesh is not a primitive test).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from armcli.analysis.support import convex_hull
from armcli.io.scene import Scene, SceneObject, Shape

CIRCLE_POINTS = 32  # a round outline's polygon


def _local(shape: Shape, point: np.ndarray) -> np.ndarray:
    T = shape.T_frame_shape
    return np.asarray(T[:3, :3].T @ (np.asarray(point, dtype=float) - T[:3, 3]))


def depth(shape: Shape, point: np.ndarray) -> float:
    """How deep [m] a point of the shape's frame lies inside a primitive (<= 0: not inside).

    The distance to the nearest face: a tool point this deep is inside the object however
    the tool comes within that distance of it. 0 for a mesh (no primitive test).
    """
    p = _local(shape, point)
    d = shape.dimensions
    if shape.kind == "box":
        return float(np.min(np.asarray(d) / 2 - np.abs(p)))
    if shape.kind == "sphere":
        return d[0] - float(np.linalg.norm(p))
    if shape.kind in ("cylinder", "cone"):  # SolidPrimitive: [height, radius], axis z, centred
        h, r = d
        rho = math.hypot(p[0], p[1])
        if shape.kind == "cylinder":
            return min(r - rho, h / 2 - abs(float(p[2])))
        side = (r * (h / 2 - float(p[2])) / h - rho) * h / math.hypot(h, r)  # the slanted side
        return min(side, float(p[2]) + h / 2)
    return 0.0


def world_objects(scene: Scene) -> Iterator[SceneObject]:
    """The objects standing in the world frame (not fixed to a robot link)."""
    return (o for o in scene.objects if not o.frame)


def containing(scene: Scene, point: np.ndarray, deeper: float = 0.0) -> str | None:
    """The id of a world object whose primitive holds `point` [m] deeper than `deeper`."""
    for obj in world_objects(scene):
        if any(depth(s, point) > deeper for s in obj.shapes):
            return obj.id
    return None


def _points(shape: Shape) -> np.ndarray:
    """Points [m] of the shape's frame whose convex hull contains its outline from above."""
    d = shape.dimensions
    if shape.kind == "mesh":
        assert shape.vertices is not None
        local = np.asarray(shape.vertices, dtype=float)
    elif shape.kind == "box":
        local = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        local = local * np.asarray(d) / 2
    else:
        r = d[0] if shape.kind == "sphere" else d[1]
        half = d[0] if shape.kind == "sphere" else d[0] / 2
        a = np.linspace(0.0, 2 * math.pi, CIRCLE_POINTS, endpoint=False)
        ring = np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
        # a sphere's or an upright cylinder's outline; a tilted one's hull is still inside this
        local = np.concatenate([np.column_stack([ring, np.full(len(a), z)]) for z in (-half, half)])
        if shape.kind == "sphere":
            local = np.concatenate([local, [[0, 0, -r], [0, 0, r]]])
    T = shape.T_frame_shape
    return np.asarray(local @ T[:3, :3].T + T[:3, 3])


def outline(obj: SceneObject) -> tuple[list[tuple[float, float]], float, float]:
    """An object's outline from above (convex, counter-clockwise) and its lowest and top z."""
    pts = np.concatenate([_points(s) for s in obj.shapes])
    hull = convex_hull([(float(x), float(y)) for x, y in pts[:, :2]])
    return hull, float(pts[:, 2].min()), float(pts[:, 2].max())
