"""Around a placed pose: how far the base may stand off it and the target stay reachable.

Per axis (x, y, yaw, the others held at the pose), the interval of poses that still serve
the target: poses one STEP apart outward (no coarser than one cell of the test's reference
grid, 1 cm and 1 degree) judged in order until one does not serve, then REFINE poses
between the last that served and it. The arm's reach is computed for a whole row of poses
at once (`Judge.reach`); collisions and the tip-over margin pose by pose, inside out.

A navigation stack parks within a radius and a heading band of its goal, both at once
(Nav2's goal checker: `xy_goal_tolerance`, `yaw_goal_tolerance`). The Nav2 goal is moved
from the placed pose (on the region's edge: a constraint stops the least driving there)
toward the intervals' middle, and the two tolerances start at half the room the intervals
leave it and are halved until every pose on the band's edge (eight directions, at both
ends of the heading band, and the heading band alone) serves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from armcli.plan.mobile.judge import Judge, Verdict

STEPS = (0.01, 0.01, math.radians(1.0))  # [m, m, rad] between two poses judged per axis
SPANS = (1.0, 1.0, math.pi)  # [m, m, rad] an interval is not searched beyond this
REFINE = 8  # poses judged between the last serving one and the first that does not
HALVINGS = 8  # rounds of halving the Nav2 tolerances before giving up (0, 0)
DIRECTIONS = 8  # around the xy tolerance circle
BLOCK = 24  # poses per row whose reach is computed at a time (a planar arm; a band fits)


@dataclass(frozen=True)
class Region:
    """The intervals per axis and the Nav2 goal tolerances, about the placed pose."""

    x: tuple[float, float]  # [m]
    y: tuple[float, float]  # [m]
    yaw: tuple[float, float]  # [rad]
    xy_tolerance: float  # [m] any pose this near the goal ...
    yaw_tolerance: float  # [rad] ... and turned this little from it still serves
    goal: tuple[float, float, float]  # the Nav2 goal: toward the intervals' middle


def _first_failing(judge: Judge, best: Verdict, rows: list[np.ndarray]) -> list[int]:
    """Per row of poses: the index of the first pose that does not serve (its length if none).

    A planar arm's reach comes for all rows at once, BLOCK poses of each at a time (a row
    mostly fails within its first few: the rest are never computed); another arm's inverse
    kinematics runs pose by pose, each seeded with the previous pose's configuration. Poses
    are judged inside out and a row stops at its first failure.
    """
    if judge.mobile.planar is None:
        return [_first_failing_ik(judge, best, poses) for poses in rows]
    out = [len(poses) for poses in rows]
    open_rows = [r for r, poses in enumerate(rows) if len(poses)]
    lo = 0
    while open_rows:
        hi = lo + BLOCK
        blocks = [rows[r][lo:hi] for r in open_rows]
        q, errors = judge.reach(np.concatenate(blocks), best.q)
        at, still = 0, []
        for r, poses in zip(open_rows, blocks, strict=True):
            for i, pose in enumerate(poses):
                if not judge.best(pose, q[at + i], errors[at + i]).ok:
                    out[r] = lo + i
                    break
            else:
                if hi < len(rows[r]):
                    still.append(r)
            at += len(poses)
        open_rows, lo = still, hi
    return out


def _first_failing_ik(judge: Judge, best: Verdict, poses: np.ndarray) -> int:
    """`_first_failing` of one row for an arm without a closed form (seeded IK per pose)."""
    seed = best.q
    for i, pose in enumerate(poses):
        qs, es = judge.reach(pose[None, :], seed)
        v = judge.best(pose, qs[0], es[0])
        if not v.ok:
            return i
        seed = v.q
    return len(poses)


def _extents(judge: Judge, best: Verdict) -> list[float]:
    """How far [m or rad] the pose may move along each axis and direction and serve.

    In the order (x-, y-, yaw-, x+, y+, yaw+): a row of poses one STEP apart per axis and
    direction, then REFINE poses between the last that served and the first that did not.
    """
    base = np.asarray(best.base, dtype=float)
    moves = [(k, sign) for sign in (-1.0, 1.0) for k in range(3)]
    steps = [STEPS[k] * np.arange(1, math.ceil(SPANS[k] / STEPS[k]) + 1) for k, _ in moves]

    def row(k: int, sign: float, ts: np.ndarray) -> np.ndarray:
        unit = np.zeros(3)
        unit[k] = sign
        return base + ts[:, None] * unit

    firsts = _first_failing(
        judge, best, [row(k, s, ts) for (k, s), ts in zip(moves, steps, strict=True)]
    )
    goods, betweens = [], []
    for ts, i in zip(steps, firsts, strict=True):
        good = float(ts[i - 1]) if i > 0 else 0.0
        goods.append(good)
        bad = float(ts[i]) if i < len(ts) else good
        betweens.append(np.linspace(good, bad, REFINE + 2)[1:-1] if i < len(ts) else ts[:0])
    fine = _first_failing(
        judge, best, [row(k, s, b) for (k, s), b in zip(moves, betweens, strict=True)]
    )
    return [float(b[k - 1]) if k > 0 else g for b, k, g in zip(betweens, fine, goods, strict=True)]


def _band(best: Verdict, r: float, theta: float) -> np.ndarray:
    """The poses on the edge of the tolerance band around the placed pose."""
    x, y, yaw = best.base
    poses = [(x, y, yaw - theta), (x, y, yaw + theta)]
    for k in range(DIRECTIONS):
        a = 2.0 * math.pi * k / DIRECTIONS
        for dyaw in (-theta, theta):
            poses.append((x + r * math.cos(a), y + r * math.sin(a), yaw + dyaw))
    return np.array(poses)


def _tolerances(judge: Judge, at: Verdict, r: float, theta: float) -> tuple[float, float]:
    """The largest (r, theta) halvings of the given ones whose band around `at` serves."""
    for _ in range(HALVINGS):
        band = _band(at, r, theta)
        if _first_failing(judge, at, [band])[0] == len(band):
            return r, theta
        r, theta = 0.5 * r, 0.5 * theta
    return 0.0, 0.0


def _goal(judge: Judge, best: Verdict, lo: list[float], hi: list[float]) -> Verdict:
    """The Nav2 goal: toward the intervals' middle, where there is room on every side.

    The least-driving pose lies where a constraint stops it (on the region's edge): Nav2
    could park no nearer than that. The goal moves toward the middle of the intervals (all
    the way, half, a quarter) to the first such pose that still serves.
    """
    b = np.asarray(best.base, dtype=float)
    middle = b + 0.5 * (np.array(hi) - np.array(lo))
    for share in (1.0, 0.5, 0.25):
        pose = b + share * (middle - b)
        v = judge.at(pose, best.q)
        if v.ok:
            return v
    return best


def region(judge: Judge, best: Verdict) -> Region:
    """The region around the placed pose `best` (see the module docstring)."""
    found = _extents(judge, best)
    lo, hi = found[:3], found[3:]
    goal = _goal(judge, best, lo, hi)
    g, b = np.asarray(goal.base, dtype=float), np.asarray(best.base, dtype=float)
    room = [min(g[k] - (b[k] - lo[k]), (b[k] + hi[k]) - g[k]) for k in range(3)]
    # both at once use up what each alone may: start from half of each
    r, theta = _tolerances(judge, goal, 0.5 * min(room[0], room[1]), 0.5 * room[2])
    return Region(
        x=(float(b[0] - lo[0]), float(b[0] + hi[0])),
        y=(float(b[1] - lo[1]), float(b[1] + hi[1])),
        yaw=(float(b[2] - lo[2]), float(b[2] + hi[2])),
        xy_tolerance=r,
        yaw_tolerance=theta,
        goal=(float(g[0]), float(g[1]), float(g[2])),
    )
