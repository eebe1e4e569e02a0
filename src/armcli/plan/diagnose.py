"""Why planning failed: is the goal cut off from the start, or did the planner run out of time?

(And after a failed IK: does the tool reach the point only in collision? `reached_in_collision`.)

OMPL only reports that it found no path within the timeout, which reads as "try longer"
even when no path exists. Called after such a failure, `connectivity` searches the free
joint space itself, cheaply and deterministically, with the planner's own checks (the
padded `free` and `motion_free` at its step):

- up to GRID_MAX_JOINTS joints, a grid over the joint box (about GRID_CELLS cells): a
  flood fill from the start over cells whose centre is free, each joined to a neighbour
  (one index apart in one joint) by a free straight motion. The goal is cut off when no
  filled cell joins it. A passage narrower than a cell can be missed, so the verdict
  names the resolution;
- more joints: a seeded roadmap (ROADMAP_SAMPLES random free states, each joined to its
  ROADMAP_NEIGHBOURS nearest by free motions). Joined start and goal prove a path; apart
  they are evidence only.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from armcli.plan.api import PlanningContext
from armcli.plan.collision import CollisionChecker
from armcli.plan.ik import solve_ik, tool_pose
from armcli.robot.frames import rpy_rotation

GRID_MAX_JOINTS = 3
GRID_CELLS = 4096  # the grid's size in all: 64 per joint for 2 joints, 16 for 3
ROADMAP_SAMPLES = 400
ROADMAP_NEIGHBOURS = 6


@dataclass(frozen=True)
class Connectivity:
    """Whether the free space joins start and goal (None: not known), and how it was found."""

    connected: bool | None
    method: str  # "a 64 x 64 grid of the joint space (0.0245 rad)", ...

    def explain(self, timeout: float) -> str:
        """The failure's message: the goal cut off, or a path that exists but was not found."""
        if self.connected is False:
            return (
                f"no path: the goal is cut off from the start: {self.method} joins no "
                "free region around the start to the goal's (an obstacle separates "
                "them; a longer --timeout will not help)"
            )
        if self.connected:
            return (
                f"no collision-free path found within {timeout:g} s, but a path exists "
                f"({self.method} joins start and goal): try a longer --timeout or "
                "another --seed"
            )
        return (
            f"no collision-free path found within {timeout:g} s, and {self.method} did not "
            "join start and goal either: the goal may be cut off from the start"
        )


def connectivity(
    checker: CollisionChecker,
    lower: np.ndarray,
    upper: np.ndarray,
    start: np.ndarray,
    goal: np.ndarray,
    *,
    step: float,
    seed: int = 0,
) -> Connectivity:
    """Search the free space between `start` and `goal` (module docstring)."""
    n = len(start)
    if n <= GRID_MAX_JOINTS:
        return _grid(checker, lower, upper, start, goal, step)
    return _roadmap(checker, lower, upper, start, goal, step, seed)


def _grid(
    checker: CollisionChecker,
    lower: np.ndarray,
    upper: np.ndarray,
    start: np.ndarray,
    goal: np.ndarray,
    step: float,
) -> Connectivity:
    n = len(start)
    per = max(4, round(GRID_CELLS ** (1.0 / n)))
    width = (upper - lower) / per

    def centre(idx: tuple[int, ...]) -> np.ndarray:
        return np.asarray(lower + width * (np.array(idx) + 0.5), dtype=float)

    free = {idx: checker.free(centre(idx)) for idx in itertools.product(range(per), repeat=n)}

    def around(x: np.ndarray) -> list[tuple[int, ...]]:
        """Free cells at or next to x's that a free motion from x reaches."""
        home = np.clip(((x - lower) / np.where(width > 0, width, 1.0)).astype(int), 0, per - 1)
        out = []
        for d in itertools.product((-1, 0, 1), repeat=n):
            idx = tuple(int(v) for v in home + np.array(d))
            inside = all(0 <= v < per for v in idx) and free[idx]
            if inside and checker.motion_free(x, centre(idx), step):
                out.append(idx)
        return out

    goal_cells = set(around(goal))
    seen = set(around(start))
    todo = list(seen)
    while todo and not seen & goal_cells:
        idx = todo.pop()
        for axis, d in itertools.product(range(n), (-1, 1)):
            nxt = list(idx)
            nxt[axis] += d
            key = tuple(nxt)
            if not 0 <= key[axis] < per or key in seen or not free[key]:
                continue
            if checker.motion_free(centre(idx), centre(key), step):
                seen.add(key)
                todo.append(key)
    cells = " x ".join([str(per)] * n)
    method = f"a {cells} grid of the joint space ({_fmt_width(width)})"
    return Connectivity(bool(seen & goal_cells), method)


def _fmt_width(width: np.ndarray) -> str:
    return "cells of " + ", ".join(f"{w:.3g}" for w in dict.fromkeys(np.round(width, 6)))


def _roadmap(
    checker: CollisionChecker,
    lower: np.ndarray,
    upper: np.ndarray,
    start: np.ndarray,
    goal: np.ndarray,
    step: float,
    seed: int,
) -> Connectivity:
    rng = np.random.default_rng(seed)
    samples = rng.uniform(lower, upper, size=(ROADMAP_SAMPLES, len(start)))
    nodes = np.vstack([start, goal, samples[[checker.free(x) for x in samples]]])
    parent = list(range(len(nodes)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(len(nodes)):
        dist = np.linalg.norm(nodes - nodes[i], axis=1)
        for j in np.argsort(dist)[1 : ROADMAP_NEIGHBOURS + 1]:
            a, b = root(i), root(int(j))
            if a != b and checker.motion_free(nodes[i], nodes[int(j)], step):
                parent[a] = b
        if root(0) == root(1):
            break
    joined = root(0) == root(1)
    method = f"a {len(nodes) - 2}-state random roadmap of the free space"
    return Connectivity(True if joined else None, method)


def reached_in_collision(
    ctx: PlanningContext,
    xyz: Sequence[float],
    rpy: Sequence[float] | None,
    start: np.ndarray,
    seed: int,
) -> tuple[str, str] | None:
    """After IK found no collision-free solution: what a solution reaching `xyz` hits.

    IK again, with the same target, orientation rule (plan.api.solve_goal) and seed but
    collisions allowed; None when even that does not reach the point (it is out of reach).
    """
    robot = ctx.robot
    rotation = None
    if rpy is not None:
        rotation = rpy_rotation(rpy)
    elif len(robot.joints) >= 6:
        rotation = tool_pose(robot, start)[1]
    res = solve_ik(robot, np.asarray(list(xyz), dtype=float), rotation, seed_x=start, seed=seed)
    return None if res.x is None else ctx.checker.first_collision(res.x, every_pair=True)
