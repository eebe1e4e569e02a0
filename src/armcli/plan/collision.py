"""Collision checking for planning: robot links, scene objects and the ground, through coal.

Self-collision pairs are filtered by the allowed-collision matrix (`disabled`: the pairs
`ros-package` writes into the SRDF, or a given SRDF's). Pairs whose relative pose no
planned joint changes (two links on the same rigid body, a scene object and an unmoved
link) are checked once at the start and goal (`first_collision(..., every_pair=True)`)
and left out of the planner's per-state check, where only moving pairs can change.
The checks run in the compiled planner (plan.native) where it is installed: the same
geometry, pairs, margins and coal queries, without a Python call per state.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.io.scene import Scene, Shape
from armcli.plan.native import compiled_scene, load
from armcli.plan.robot import PlanRobot
from armcli.robot.collision import add_pairs
from armcli.robot.frames import frame_id

GROUND_ID = "ground"  # the name the ground plane has in collision reports
# Every collision query asks for contacts: coal 3.0.3's boolean-only query (Pinocchio's
# default) can miss a penetration, e.g. a cylinder 7.9 mm into a box (found by the reach
# helper's brute-force reference); with contacts its GJK runs to the end.
PADDING = 0.005  # [m] clearance the planner keeps (CollisionChecker.pad)


@dataclass(frozen=True)
class Body:
    """One collision geometry's owner: a robot link, a scene object or the ground."""

    name: str
    moves_with: frozenset[str]  # planned joints that move it (empty: static)
    is_link: bool


def _coal_shape(shape: Shape) -> Any:
    import coal

    d = shape.dimensions
    if shape.kind == "box":
        return coal.Box(*d)
    if shape.kind == "sphere":
        return coal.Sphere(d[0])
    if shape.kind == "cylinder":  # SolidPrimitive: [height, radius]
        return coal.Cylinder(d[1], d[0])
    if shape.kind == "cone":
        return coal.Cone(d[1], d[0])
    assert shape.vertices is not None and shape.triangles is not None
    bvh = coal.BVHModelOBBRSS()  # addSubModel takes std::vectors, not arrays (issue 42)
    bvh.beginModel(len(shape.triangles), len(shape.vertices))
    bvh.addVertices(np.asarray(shape.vertices, dtype=np.float64))
    bvh.addTriangles(np.asarray(shape.triangles, dtype=np.int64))
    bvh.endModel()
    return bvh


def _moving_joints(robot: PlanRobot) -> dict[int, frozenset[str]]:
    """Pinocchio joint id -> the planned joints above it (followers count as their leader)."""
    model = robot.model
    leader = {m.follower: m.leader for m in robot.mimic}
    planned = set(robot.joints)
    out = {}
    for jid in range(model.njoints):
        names = {str(model.names[k]) for k in model.supports[jid] if k > 0}
        names = {leader.get(n, n) for n in names}
        out[jid] = frozenset(names & planned)
    return out


class CollisionChecker:
    """The robot's collision model plus obstacles, with the pairs to check.

    The checks run in the compiled planner (plan.native) when it is installed, else through
    Pinocchio's Python bindings (`native=False` forces that path; tests compare the two).
    """

    def __init__(
        self,
        robot: PlanRobot,
        scene: Scene,
        disabled: Iterable[tuple[str, str]],
        *,
        native: bool = True,
    ) -> None:
        import pinocchio as pin

        self.pin = pin
        self.robot = robot
        self.model = robot.model
        gmodel = robot.geometry.copy()
        moving = _moving_joints(robot)
        frames = self.model.frames
        self.bodies: list[Body] = [
            Body(str(frames[g.parentFrame].name), moving[g.parentJoint], True)
            for g in gmodel.geometryObjects
        ]
        for obj in scene.objects:
            fid = _frame(self.model, obj.frame) if obj.frame else 0
            joint = frames[fid].parentJoint if obj.frame else 0
            T_joint_frame = frames[fid].placement if obj.frame else pin.SE3.Identity()
            for k, shape in enumerate(obj.shapes):
                placement = T_joint_frame * pin.SE3(shape.T_frame_shape)
                geom = pin.GeometryObject(
                    f"{obj.id}#{k}", joint, fid, placement, _coal_shape(shape)
                )
                gmodel.addGeometryObject(geom)
                self.bodies.append(Body(obj.id, moving[joint], False))
        if robot.mobile:
            import coal

            plane = coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0)
            gmodel.addGeometryObject(pin.GeometryObject(GROUND_ID, 0, 0, pin.SE3.Identity(), plane))
            self.bodies.append(Body(GROUND_ID, frozenset(), False))
        self.pairs = self._pairs(gmodel, {_key(a, b) for a, b in disabled})
        self.gmodel = gmodel
        # a pair whose two bodies move with the same joints keeps its relative pose
        self.moving = [
            self.bodies[i].moves_with != self.bodies[j].moves_with for i, j in self.pairs
        ]
        mod = load() if native else None
        names = [b.name for b in self.bodies]
        self.native = (
            compiled_scene(mod, robot, gmodel, self.pairs, self.moving, names) if mod else None
        )
        if self.native is None:
            self._python_checks()

    @property
    def data(self) -> Any:
        """The robot's pinocchio.Data for this thread (Robot.data, shared by its users)."""
        return self.robot.robot.data

    def _python_checks(self) -> None:
        """Pinocchio's GeometryData per use: every pair, the planner's (padded), moving exact."""
        pin = self.pin
        self.gdata_all = pin.GeometryData(self.gmodel)
        self.gdata = pin.GeometryData(self.gmodel)  # moving pairs, padded: the planner's
        self.gdata_moving = pin.GeometryData(self.gmodel)  # moving pairs, exact
        for k, moves in enumerate(self.moving):
            if not moves:
                self.gdata.deactivateCollisionPair(k)  # their relative pose never changes
                self.gdata_moving.deactivateCollisionPair(k)
        for gdata in (self.gdata_all, self.gdata, self.gdata_moving):
            for req in gdata.collisionRequests:  # exact: see the note at GROUND_ID
                req.enable_contact = True
        self._broadphase()

    def _pairs(self, gmodel: Any, disabled: set[tuple[str, str]]) -> list[tuple[int, int]]:
        """Register the pairs to check (robot.collision.add_pairs: one set-up for every checker).

        Bodies of one owner never; two scene objects never; two links unless the matrix
        disables them; the ground and a link of the robot's root never (it stands on it).
        """
        bodies = self.bodies
        robot_root = {b.name for b in bodies if b.is_link and not b.moves_with}

        def keep(i: int, j: int) -> bool:
            a, b = bodies[i], bodies[j]
            if not a.is_link and not b.is_link:
                return False
            if a.is_link and b.is_link and _key(a.name, b.name) in disabled:
                return False
            ground = GROUND_ID in (a.name, b.name)
            return not (ground and (a.name in robot_root or b.name in robot_root))

        return add_pairs(gmodel, [b.name for b in bodies], keep)

    def pad(self, padding: float, ends: Iterable[np.ndarray]) -> None:
        """Plan `padding` [m] clear; a pair closer than that at an end, half its clearance there.

        The planner's check only: a path then keeps a clearance that the trajectory's small
        deviations between its points (timing) cannot eat; certification checks with none.
        A pair left with no clearance at all (as before) could be planned to touch, and the
        timed motion's deviation then made contact (found on the Panda's link2 and link5).
        """
        margins = np.full(len(self.pairs), float(padding))
        gdata = self.pin.GeometryData(self.gmodel)
        for x in ends:
            close = self._within(x, float(padding))
            q = self.robot.q(x)
            self.pin.updateGeometryPlacements(self.model, self.data, self.gmodel, gdata, q)
            for k in close:
                d = self.pin.computeDistance(self.gmodel, gdata, k).min_distance
                margins[k] = min(margins[k], max(0.5 * d, 0.0))
        if self.native is not None:
            self.native.set_margins(margins)
            return
        for req, margin in zip(self.gdata.collisionRequests, margins, strict=True):
            req.security_margin = float(margin)
        self._broadphase()

    def _within(self, x: np.ndarray, margin: float) -> list[int]:
        """The moving pairs closer than `margin` [m] at `x`."""
        if self.native is not None:
            return list(self.native.colliding(_x(x), margin))
        gdata = self.pin.GeometryData(self.gmodel)
        for k, (req, moves) in enumerate(zip(gdata.collisionRequests, self.moving, strict=True)):
            req.security_margin, req.enable_contact = margin, True
            if not moves:
                gdata.deactivateCollisionPair(k)
        q = self.robot.q(x)
        self.pin.computeCollisions(self.model, self.data, self.gmodel, gdata, q, False)
        return [k for k, res in enumerate(gdata.collisionResults) if res.isCollision()]

    def _broadphase(self) -> None:
        """Coal's dynamic AABB tree over the planner's pairs, as roboplan uses.

        It culls pairs whose bounding boxes (grown by the padding) are apart: ~5x faster on
        the Panda in bench/bench_plan.py's scenes, with the same verdicts.
        """
        self.manager = self.pin.BroadPhaseManager_DynamicAABBTreeCollisionManager(
            self.model, self.gmodel, self.gdata
        )

    def first_collision(self, x: np.ndarray, *, every_pair: bool = False) -> tuple[str, str] | None:
        """The first colliding pair at planned joint values `x` (names), or None.

        Exact geometry (no padding); `every_pair` also checks the pairs no planned joint moves.
        """
        if self.native is not None:
            k = self.native.first_collision(_x(x), every_pair)
            return None if k < 0 else self.pair_names(k)
        gdata = self.gdata_all if every_pair else self.gdata_moving
        q = self.robot.q(x)
        if not self.pin.computeCollisions(self.model, self.data, self.gmodel, gdata, q, True):
            return None
        for k, res in enumerate(gdata.collisionResults):
            if res.isCollision():
                return self.pair_names(k)
        return None  # pragma: no cover - computeCollisions said there was one

    def pair_names(self, k: int) -> tuple[str, str]:
        """The two bodies of pair `k` (links, scene objects, the ground)."""
        i, j = self.pairs[k]
        return self.bodies[i].name, self.bodies[j].name

    def free(self, x: np.ndarray) -> bool:
        """Whether `x` is collision-free (moving pairs only, padded: the planner's check)."""
        if self.native is not None:
            return bool(self.native.free(_x(x)))
        pin = self.pin
        pin.updateGeometryPlacements(
            self.model, self.data, self.gmodel, self.gdata, self.robot.q(x)
        )
        self.manager.update(False)
        return not pin.computeCollisions(self.manager, True)

    def motion_free(self, xa: np.ndarray, xb: np.ndarray, step: float) -> bool:
        """Whether the straight joint-space segment is free, checked every `step` [rad or m].

        The end first, then midpoints by bisection (as OMPL's discrete motion validator and
        roboplan do): a blocked segment is usually refused after a few checks.
        """
        if self.native is not None:
            return bool(self.native.motion_free(_x(xa), _x(xb), float(step)))
        n = max(1, math.ceil(float(np.max(np.abs(xb - xa))) / step))
        return all(self.free(xa + (xb - xa) * (k / n)) for k in bisection_order(n))


def _x(x: Any) -> np.ndarray:
    """Joint values as the extension takes them: contiguous float64."""
    return np.ascontiguousarray(x, dtype=np.float64)


def bisection_order(n: int) -> list[int]:
    """1..n, the end first, then the midpoints of ever smaller intervals (each once)."""
    out, seen = [n], {0, n}
    intervals = [(0, n)]
    while intervals:
        nxt = []
        for lo, hi in intervals:
            mid = (lo + hi) // 2
            if mid not in seen:
                seen.add(mid)
                out.append(mid)
            if mid - lo > 1:
                nxt.append((lo, mid))
            if hi - mid > 1:
                nxt.append((mid, hi))
        intervals = nxt
    return out


def _key(a: str, b: str) -> tuple[str, str]:
    return (a, b) if a <= b else (b, a)


def _frame(model: Any, name: str) -> int:
    """The frame an object's `frame_id` names: the link first (a joint may share its name)."""
    return frame_id(model, name)
