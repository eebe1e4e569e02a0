"""A collision-free joint-space path: RRT-Connect (or another OMPL planner), then shortcutting.

A straight segment that is free is taken as it is (no sampling needed). Otherwise, with the
compiled planner installed (plan.native) and the default planner, RRT-Connect runs in C++
(plan/_native/rrt.cpp): two trees from start and goal, extensions of at most RANGE toward
uniform samples (toward the other tree's root with probability GOAL_BIAS), edges checked at
`step` [rad or m] in bisection order. An attempt that grows ATTEMPT_NODES nodes without
meeting gives way to a fresh one with the next seed, until the timeout. Attempts can run on
THREADS threads at once; the path is always the lowest-numbered successful attempt's, so a
seed gives the same path whatever the thread count (one by default: with two, the second
thread's attempt is mostly wasted work, since the first's result must be waited for). The
other planners (`--planner`), and every planner without the extension, are OMPL's with the
checker as a Python validity callback. Every random number is seeded, so a seed gives the
same path whenever the planner finishes before the timeout.

Shortcutting: the greedy pass (from each waypoint, the farthest one reachable in a straight
line), then seeded random shortcuts between points on the path, then the greedy pass again;
compiled with the planner (more tries: they are cheap there), or in Python with numpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from armcli.defaults import PLANNERS
from armcli.errors import InputError, PlanningError
from armcli.plan.collision import CollisionChecker

SHORTCUT_TRIES = 20  # random shortcut attempts after the greedy pass
SHORTCUT_PATIENCE = 5  # stop after this many failed attempts in a row (as roboplan does)
# The compiled RRT-Connect, tuned on bench/plan_peers.py's slot scene (30 queries, CPU time
# to solve, median): range 0.5: 0.38 s, 0.7: 0.31, 0.8: 0.21, 1.0: 0.15, 1.5: 0.25, 3.0: 0.63
# (21/30 solved within 1 s); goal bias 0.15 or bridge sampling did not help there.
RANGE = 1.0  # [rad] longest extension (Euclidean in the planned joints' values)
GOAL_BIAS = 0.05  # probability of growing toward the other tree's root
ATTEMPT_NODES = 20_000  # nodes of both trees before an attempt gives way to the next seed
THREADS = 1  # attempts run at once
# [rad] lazy edges: the trees grow with edges checked at this step; the edges of a path
# the trees meet along are checked at `step` then, and a failing one cut off (rrt.cpp).
# Tuned on a held-out set of 30 slot queries (seed 7, not the benchmark's), CPU median of
# planning + shortcutting: no laziness 179 ms, 0.1: 95, 0.2: 95, 0.3: 83-98, 0.4: 81,
# 0.5: 68-72, 0.7: 96, 1.0: 122 (every one 30/30 solved but none: 27/30).
LAZY_STEP = 0.5
COMPILED_SHORTCUT_TRIES = 100  # random shortcut attempts (roboplan's max_iters)
COMPILED_SHORTCUT_PATIENCE = 20  # stop after this many misses in a row (its convergence)
_OMPL_NAMES = {
    "rrtconnect": "RRTConnect",
    "rrt": "RRT",
    "rrtstar": "RRTstar",
    "informedrrtstar": "InformedRRTstar",
    "aorrtc": "AORRTC",
}


def _ompl_path(
    checker: CollisionChecker,
    lower: np.ndarray,
    upper: np.ndarray,
    start: np.ndarray,
    goal: np.ndarray,
    *,
    planner: str,
    timeout: float,
    seed: int,
    step: float,
) -> np.ndarray | None:
    """OMPL's path (W, n), or None when it found none within `timeout` [s]."""
    import ompl.base as ob
    import ompl.geometric as og
    import ompl.util as ou

    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    ou.RNG.setSeed(seed)
    n = len(start)
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for i in range(n):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]) if upper[i] > lower[i] else float(lower[i]) + 1e-9)
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    free = checker.free
    setup.setStateValidityChecker(lambda s: free(np.fromiter((s[i] for i in range(n)), float, n)))
    info = setup.getSpaceInformation()
    info.setStateValidityCheckingResolution(min(1.0, step / max(space.getMaximumExtent(), 1e-9)))
    a, b = space.allocState(), space.allocState()
    for i in range(n):
        a[i], b[i] = float(start[i]), float(goal[i])
    setup.setStartAndGoalStates(a, b)
    setup.setPlanner(getattr(og, _OMPL_NAMES[planner])(info))
    status = setup.solve(timeout)
    path = None
    if setup.haveExactSolutionPath() and str(status) == "Exact solution":
        p = setup.getSolutionPath()
        path = np.array([[p.getState(k)[i] for i in range(n)] for k in range(p.getStateCount())])
    setup.clear()
    return path


def _greedy(path: np.ndarray, ok: Callable[[np.ndarray, np.ndarray], bool]) -> np.ndarray:
    """Keep only the waypoints needed: from each kept one, jump to the farthest reachable."""
    out, i = [path[0]], 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1 and not ok(path[i], path[j]):
            j -= 1
        out.append(path[j])
        i = j
    return np.array(out)


def _point_at(path: np.ndarray, cum: np.ndarray, d: float) -> tuple[int, np.ndarray]:
    """(segment index, point) at arc length `d` along the polyline."""
    k = int(np.clip(np.searchsorted(cum, d, side="right") - 1, 0, len(path) - 2))
    seg = cum[k + 1] - cum[k]
    u = 0.0 if seg <= 0 else (d - cum[k]) / seg
    return k, path[k] + (path[k + 1] - path[k]) * u


def shortcut(
    path: np.ndarray, ok: Callable[[np.ndarray, np.ndarray], bool], seed: int
) -> np.ndarray:
    """A shorter path with the same ends: greedy pass, then seeded random shortcuts."""
    path = _greedy(path, ok)
    rng = np.random.default_rng(seed)
    misses = 0
    for _ in range(SHORTCUT_TRIES):
        if len(path) < 3 or misses >= SHORTCUT_PATIENCE:
            break
        cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
        d1, d2 = np.sort(rng.uniform(0.0, cum[-1], 2))
        k1, p1 = _point_at(path, cum, d1)
        k2, p2 = _point_at(path, cum, d2)
        if k1 == k2 or not ok(p1, p2):
            misses += 1
            continue
        misses = 0
        path = np.vstack([path[: k1 + 1], p1, p2, path[k2 + 1 :]])
        path = _drop_repeats(path)
    return _greedy(path, ok)


def _drop_repeats(path: np.ndarray) -> np.ndarray:
    keep = [0] + [k for k in range(1, len(path)) if np.any(path[k] != path[k - 1])]
    return path[keep]


def plan_path(
    checker: CollisionChecker,
    lower: np.ndarray,
    upper: np.ndarray,
    start: np.ndarray,
    goal: np.ndarray,
    *,
    planner: str = "rrtconnect",
    timeout: float = 1.0,
    seed: int = 0,
    step: float = 0.02,
) -> np.ndarray:
    """A collision-free polyline (W, n) from start to goal; PlanningError when none is found."""
    if planner not in PLANNERS:
        raise InputError(f"unknown planner {planner!r}; valid: {', '.join(PLANNERS)}",
                         field="planner")  # fmt: skip
    if not (math.isfinite(timeout) and timeout > 0):
        raise InputError(f"must be > 0 s, got {timeout:g}", field="timeout")

    def ok(a: np.ndarray, b: np.ndarray) -> bool:
        return checker.motion_free(a, b, step)

    if ok(start, goal):
        return np.array([start, goal])
    if checker.native is not None and planner == "rrtconnect":
        return _compiled_path(checker, start, goal, timeout=timeout, seed=seed, step=step)
    raw: Any = _ompl_path(checker, lower, upper, start, goal, planner=planner,
                          timeout=timeout, seed=seed, step=step)  # fmt: skip
    if raw is None:
        raise PlanningError("no-path", f"no collision-free path found within {timeout:g} s")
    raw[0], raw[-1] = start, goal
    return shortcut(raw, ok, seed)


def _compiled_path(
    checker: CollisionChecker, start: np.ndarray, goal: np.ndarray, *, timeout: float,
    seed: int, step: float,
) -> np.ndarray:  # fmt: skip
    """RRT-Connect and shortcutting in the compiled planner (plan/_native/rrt.cpp)."""
    native = checker.native
    assert native is not None
    raw, _stats = native.plan(
        np.ascontiguousarray(start, dtype=float), np.ascontiguousarray(goal, dtype=float),
        range=RANGE, goal_bias=GOAL_BIAS, step=step, timeout=timeout, seed=seed,
        threads=THREADS, attempt_nodes=ATTEMPT_NODES, lazy_step=max(LAZY_STEP, step),
    )  # fmt: skip
    if raw is None:
        raise PlanningError("no-path", f"no collision-free path found within {timeout:g} s")
    raw[0], raw[-1] = start, goal
    path: np.ndarray = native.shortcut(raw, step, seed, COMPILED_SHORTCUT_TRIES,
                                       COMPILED_SHORTCUT_PATIENCE)  # fmt: skip
    return path
