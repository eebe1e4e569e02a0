"""A robot's collision geometry and the pairs of it to check: one set-up for every checker.

Pinocchio's GeometryModel holds one object per `<collision>` element, each owned by a link
(a planner adds scene objects and the ground, owned by their names). A pair of objects is
checked when their owners differ and the caller's rule keeps it: `check` leaves out
parent-child links, the collision matrix keeps the pairs MoveIt does not decide by
construction, `plan` drops the pairs its SRDF disables. `add_pairs` registers them in
object order (i < j), so a pair's index is its index in the GeometryData's requests and
results; `SelfCollision` is the robot's own geometry with its pairs, ready to pose.
`placements` and `box_corners` pose the objects at a configuration (the base placement's
floor plan and plot).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.robot.model import Robot


def geometry_links(model: Any, gmodel: Any) -> list[str]:
    """The link that owns each collision object, in object order."""
    return [str(model.frames[g.parentFrame].name) for g in gmodel.geometryObjects]


def placements(robot: Robot, gmodel: Any, q: ArrayLike) -> NDArray[np.float64]:
    """Each collision object's pose T_root_object (N, 4, 4) at configuration q [m]."""
    import pinocchio as pin

    gdata = pin.GeometryData(gmodel)
    pin.updateGeometryPlacements(robot.model, robot.data, gmodel, gdata, np.asarray(q, dtype=float))
    return np.array([M.homogeneous for M in gdata.oMg], dtype=float).reshape(-1, 4, 4)


def box_corners(robot: Robot, gmodel: Any, q: ArrayLike) -> list[tuple[str, NDArray[np.float64]]]:
    """Each collision object's link and its local bounding box's 8 corners (8, 3) at q [m].

    The box is the shape's own axis-aligned one, turned with the object: a conservative
    outline for a floor plan seen from above.
    """
    links = geometry_links(robot.model, gmodel)
    out = []
    for T, g, link in zip(placements(robot, gmodel, q), gmodel.geometryObjects, links, strict=True):
        g.geometry.computeLocalAABB()
        lo, hi = np.asarray(g.geometry.aabb_local.min_), np.asarray(g.geometry.aabb_local.max_)
        box = np.array(
            [[a, b, c] for a in (lo[0], hi[0]) for b in (lo[1], hi[1]) for c in (lo[2], hi[2])]
        )
        out.append((link, box @ T[:3, :3].T + T[:3, 3]))
    return out


def add_pairs(
    gmodel: Any, owners: Sequence[str], keep: Callable[[int, int], bool]
) -> list[tuple[int, int]]:
    """Register the object pairs (i < j) of different owners that `keep(i, j)` lets through.

    Returns them in registration order: pair k is `gmodel.collisionPairs[k]`.
    """
    import pinocchio as pin

    pairs = []
    for i, j in itertools.combinations(range(len(owners)), 2):
        if owners[i] != owners[j] and keep(i, j):
            gmodel.addCollisionPair(pin.CollisionPair(i, j))
            pairs.append((i, j))
    return pairs


class SelfCollision:
    """A robot's collision geometry with the link pairs `keep(link1, link2)` lets through.

    `pairs[k]` names pair k's links, in object order; `gdata` holds each pair's request
    (a caller may set its security margin) and result.
    """

    def __init__(
        self, robot: Robot, keep: Callable[[str, str], bool], gmodel: Any | None = None
    ) -> None:
        """`gmodel`: the geometry to use (default: `Robot.collision_model()`, meshes as given)."""
        import pinocchio as pin

        self.robot = robot
        self.gmodel = gmodel if gmodel is not None else robot.collision_model()
        links = geometry_links(robot.model, self.gmodel)
        found = add_pairs(self.gmodel, links, lambda i, j: keep(links[i], links[j]))
        self.objects = found  # (i, j) object indices per pair
        self.pairs = [(links[i], links[j]) for i, j in found]
        self.gdata = pin.GeometryData(self.gmodel)

    def colliding(self, q: ArrayLike, active: Iterable[int] | None = None) -> list[int]:
        """The pairs (indices) in collision at configuration q, testing only `active` ones."""
        import pinocchio as pin

        robot = self.robot
        pin.updateGeometryPlacements(robot.model, robot.data, self.gmodel, self.gdata, q)
        chosen = range(len(self.pairs)) if active is None else active
        return [k for k in chosen if pin.computeCollision(self.gmodel, self.gdata, k)]
