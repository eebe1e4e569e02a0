"""A differential drive's path around the floor's objects: turn, drive straight, turn.

A diff drive cannot move sideways; it can turn in place. So a path is a polyline whose
every leg is driven straight, forward or in reverse, with a turn in place at each corner
(and at both ends to the start's and goal's yaw); its cost is the wheels' travel
(`plan.mobile.driving`). The straight rotate-drive-rotate path is taken when the floor
allows it; otherwise a roadmap of seeded Halton points where the robot may turn freely
(its outline's circle about the base clear of every object) is searched by A* with that
cost, its path checked leg by leg (each leg's swept area, each corner's turn), then
shortened by straight shortcuts. Everything here is on the conservative floor plan
(`plan.mobile.footprint`); the 3-D checker certifies the result.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass

import numpy as np

from armcli.errors import PlanningError
from armcli.plan.mobile.driving import wrap
from armcli.plan.mobile.footprint import Outline, Outlines, grown, placed, sweep

SAMPLES = 300  # roadmap points (Halton) over the floor around start, goal and objects
NEIGHBOURS = 12  # roadmap edges per point
TURN_EPS = 1e-9  # [rad] a smaller turn is none
TURN_STEP = math.radians(5.0)  # [rad] a turn is checked every this much, objects grown to match
MARGIN = 2.0  # [outline radii] the roadmap's area beyond the objects, start and goal
APPROACH = (0.25, 0.5, 0.8, 1.2)  # [m] roadmap points ahead of and behind the start and goal
# A turn in place scrubs: MuJoCo's drive turns 1.3-3 % short of its encoders and its wheels'
# midpoint slides (plan.mobile.pursuit). The search weighs a radian of turn as TURN_WEIGHT
# of driving (more than the wheels' travel, half the track) and the straight path is taken
# only if its turn at the goal is at most MAX_FINAL_TURN: the base arrives heading the
# goal's way, and what the follower corrects there is along its heading.
TURN_WEIGHT = 1.0  # [m per rad]
MAX_FINAL_TURN = math.radians(20.0)


@dataclass(frozen=True)
class Leg:
    """One straight drive at a fixed yaw, forward (+1) or reversing (-1)."""

    a: tuple[float, float]
    b: tuple[float, float]
    yaw: float  # [rad] the robot's heading while driving
    sign: float

    @property
    def length(self) -> float:
        """[m]."""
        return math.hypot(self.b[0] - self.a[0], self.b[1] - self.a[1])


@dataclass(frozen=True)
class BasePath:
    """Start and goal poses and the legs between them (a turn in place before each leg)."""

    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    legs: tuple[Leg, ...]

    @property
    def length(self) -> float:
        """[m] driven."""
        return sum(leg.length for leg in self.legs)

    @property
    def turns(self) -> list[tuple[tuple[float, float], float, float]]:
        """Every turn in place: (where, from yaw, by how much [rad]), in order."""
        out, yaw = [], self.start[2]
        where = (self.start[0], self.start[1])
        for leg in self.legs:
            out.append((where, yaw, float(wrap(np.asarray(leg.yaw - yaw)))))
            yaw, where = leg.yaw, leg.b
        out.append((where, yaw, float(wrap(np.asarray(self.goal[2] - yaw)))))
        return [t for t in out if abs(t[2]) > TURN_EPS]

    def cost(self, half_track: float) -> float:
        """[m] the wheels' travel."""
        return self.length + half_track * sum(abs(t[2]) for t in self.turns)


class FloorPlan:
    """The robot's outline among the objects' outlines: what may be driven and turned."""

    def __init__(self, robot: Outline, objects: list[Outline]) -> None:
        self.robot = robot
        self.reach = float(np.max(np.linalg.norm(robot.points, axis=1)))  # about the base
        self.objects = Outlines(objects)
        self.turning = Outlines([grown(o, self.reach * TURN_STEP / 2) for o in objects])
        self.checks = 0

    def drivable(self, leg: Leg) -> bool:
        """Whether the leg's swept area is clear of every object."""
        self.checks += 1
        return not self.objects.meets(sweep(self.robot, np.array(leg.a), np.array(leg.b), leg.yaw))

    def spinnable(self, xy: tuple[float, float]) -> bool:
        """Whether the robot may turn any amount at xy (its circle about the base is clear)."""
        return self.objects.distance(np.asarray(xy, dtype=float)) > self.reach

    def turnable(self, xy: tuple[float, float], yaw: float, by: float) -> bool:
        """Whether turning in place at xy from yaw by `by` [rad] is clear."""
        if abs(by) < 1e-12 or self.spinnable(xy):
            return True
        n = max(1, math.ceil(abs(by) / TURN_STEP))
        self.checks += n + 1
        return not any(
            self.turning.meets(placed(self.robot, xy[0], xy[1], yaw + by * k / n))
            for k in range(n + 1)
        )

    def free(self, pose: tuple[float, float, float]) -> bool:
        """Whether the robot at the pose is clear of every object."""
        self.checks += 1
        return not self.objects.meets(placed(self.robot, *pose))


def _leg(a: tuple[float, float], b: tuple[float, float], yaw_before: float) -> Leg:
    """The straight leg a -> b driven forward or reversing, whichever turns less from yaw."""
    heading = math.atan2(b[1] - a[1], b[0] - a[0])
    forward = abs(float(wrap(np.asarray(heading - yaw_before))))
    backward = abs(float(wrap(np.asarray(heading + math.pi - yaw_before))))
    if forward <= backward:
        return Leg(a, b, heading, 1.0)
    return Leg(a, b, float(wrap(np.asarray(heading + math.pi))), -1.0)


def _connects(
    plan: FloorPlan, path: list[tuple[float, float]], start_yaw: float, goal_yaw: float | None
) -> tuple[Leg, ...] | None:
    """The legs along `path` if every leg and turn is clear (goal_yaw None: no final turn)."""
    legs, yaw = [], start_yaw
    for a, b in itertools.pairwise(path):
        if math.dist(a, b) < 1e-9:
            continue
        leg = _leg(a, b, yaw)
        if not plan.turnable(a, yaw, float(wrap(np.asarray(leg.yaw - yaw)))):
            return None
        if not plan.drivable(leg):
            return None
        legs.append(leg)
        yaw = leg.yaw
    if goal_yaw is not None and not plan.turnable(
        path[-1], yaw, float(wrap(np.asarray(goal_yaw - yaw)))
    ):
        return None
    return tuple(legs)


def _final_turn(legs: tuple[Leg, ...], goal_yaw: float) -> float:
    """[rad] the turn at the goal after the last leg."""
    return abs(float(wrap(np.asarray(goal_yaw - legs[-1].yaw)))) if legs else 0.0


def _halton(n: int, base: int, skip: int) -> np.ndarray:
    out = np.empty(n)
    for i in range(n):
        f, r, k = 1.0, 0.0, i + 1 + skip
        while k > 0:
            f /= base
            r += f * (k % base)
            k //= base
        out[i] = r
    return out


def _roadmap(
    plan: FloorPlan, start: tuple[float, float, float], goal: tuple[float, float, float], seed: int
) -> np.ndarray:
    """Start, goal, the lines through them along their yaws, then Halton points.

    The points on the start's and goal's heading lines let the robot leave and arrive
    straight, without turning where it stands (beside a table, its arm reaching over it);
    the Halton points (offset by the seed) are where the robot may spin freely.
    """
    a, b = np.array(start[:2]), np.array(goal[:2])
    every = np.vstack([a, b, *(o.points for o in plan.objects.shapes)])
    lo = every.min(axis=0) - MARGIN * plan.reach
    hi = every.max(axis=0) + MARGIN * plan.reach
    lines = []
    for x, y, yaw in (start, goal):
        u = np.array([math.cos(yaw), math.sin(yaw)])
        lines += [np.array([x, y]) + sign * d * u for d in APPROACH for sign in (-1.0, 1.0)]
    raw = np.stack([_halton(SAMPLES, 2, 97 * seed), _halton(SAMPLES, 3, 97 * seed)], axis=1)
    keep = [p for p in lo + raw * (hi - lo) if plan.spinnable((float(p[0]), float(p[1])))]
    free = [p for p in lines if plan.objects.distance(p) > 0.0]
    return np.array([a, b, *free, *keep], dtype=float)


def _search(
    plan: FloorPlan, nodes: np.ndarray, start_yaw: float, goal_yaw: float, half_track: float
) -> list[int] | None:
    """Lazy A* over the roadmap, each corner's turn in the cost.

    A node's arrival is checked (its leg and the turn before it) only when the node comes
    off the queue: most legs the search considers are never driven, so never checked.
    """
    d = np.linalg.norm(nodes[:, None, :] - nodes[None, :, :], axis=2)
    k = min(NEIGHBOURS, len(nodes) - 1)
    near = np.argsort(d, axis=1)[:, 1 : k + 1]
    edges = {i: set(near[i].tolist()) for i in range(len(nodes))}
    for i in range(len(nodes)):  # symmetric
        for j in near[i]:
            edges[int(j)].add(i)
    pt = [(float(x), float(y)) for x, y in nodes]
    yaw_at: dict[int, float] = {}
    parent: dict[int, int] = {}
    heap: list[tuple[float, float, int, int]] = [(float(d[0, 1]), 0.0, 0, -1)]
    while heap:
        _, g, n, via = heapq.heappop(heap)
        if n in yaw_at:
            continue
        if via >= 0:
            final = goal_yaw if n == 1 else None
            legs = _connects(plan, [pt[via], pt[n]], yaw_at[via], final)
            if legs is None:
                continue
            yaw_at[n], parent[n] = legs[-1].yaw, via
        else:
            yaw_at[n] = start_yaw
        if n == 1:
            path = [1]
            while path[-1] != 0:
                path.append(parent[path[-1]])
            return path[::-1]
        for m in edges[n]:
            if m in yaw_at:
                continue
            leg = _leg(pt[n], pt[m], yaw_at[n])
            cost = g + leg.length + half_track * abs(float(wrap(np.asarray(leg.yaw - yaw_at[n]))))
            if m == 1:
                cost += half_track * abs(float(wrap(np.asarray(goal_yaw - leg.yaw))))
            heapq.heappush(heap, (cost + float(d[m, 1]), cost, m, n))
    return None


def _shortcut(
    plan: FloorPlan, pts: list[tuple[float, float]], start_yaw: float, goal_yaw: float
) -> tuple[Leg, ...]:
    """Greedy straight shortcuts: from each corner, the farthest later one reachable straight.

    The last leg is kept (it arrives heading the goal's way). The turns where the shortened
    path meets the rest are checked at the end; should one fail, the path found is kept as
    it is (it was checked leg by leg).
    """
    out, i, yaw = [pts[0]], 0, start_yaw
    while i < len(pts) - 1:
        last = len(pts) - 1 if i >= len(pts) - 2 else len(pts) - 2  # the last leg is kept
        for j in range(last, i, -1):
            legs = _connects(plan, [pts[i], pts[j]], yaw, None)
            if legs is not None:
                out.append(pts[j])
                yaw, i = (legs[-1].yaw if legs else yaw), j
                break
        else:  # pragma: no cover - the next corner was reachable when the path was found
            out.append(pts[i + 1])
            i += 1
    legs = _connects(plan, out, start_yaw, goal_yaw)
    if legs is None:
        legs = _connects(plan, pts, start_yaw, goal_yaw)
    assert legs is not None  # the path found was checked leg by leg
    return legs


def plan_base_path(
    plan: FloorPlan,
    start: tuple[float, float, float],
    goal: tuple[float, float, float],
    half_track: float,
    seed: int = 0,
) -> BasePath:
    """The path from start to goal (x, y, yaw) [m, m, rad]; PlanningError when there is none."""
    if not plan.free(start):
        raise PlanningError("base-start", "the robot at the start pose overlaps an object")
    if not plan.free(goal):
        raise PlanningError("base-goal", "the robot at the goal pose overlaps an object")
    a, b = (start[0], start[1]), (goal[0], goal[1])
    direct = _connects(plan, [a, b], start[2], goal[2])
    weight = max(half_track, TURN_WEIGHT)
    if direct is not None and _final_turn(direct, goal[2]) <= MAX_FINAL_TURN:
        return BasePath(start, goal, direct)
    nodes = _roadmap(plan, start, goal, seed)
    found = _search(plan, nodes, start[2], goal[2], weight)
    if found is None and direct is not None:
        return BasePath(start, goal, direct)
    if found is None:
        raise PlanningError(
            "base-path",
            f"no path for the base from ({start[0]:g}, {start[1]:g}) to ({goal[0]:.3f}, "
            f"{goal[1]:.3f}) around the scene's objects",
        )
    pts = [(float(nodes[k, 0]), float(nodes[k, 1])) for k in found]
    return BasePath(start, goal, _shortcut(plan, pts, start[2], goal[2]))
