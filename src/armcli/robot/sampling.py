"""The joint-space sampler: every sample of a robot's joint range comes from here.

`check` (gravity torques, PD stability), `tune` (the start gains), the balance search,
the workspace and the collision matrix all sample the joint range box the same way:

- a full grid of GRID_POINTS per joint while it has at most MAX_GRID points;
- else the rest pose (`robot.joints.rest`), every corner of the box while there are at
  most MAX_CORNERS (gravity torques peak there for serial arms) and seeded uniform draws.

Draws use the standard library's generator (numpy.random costs 20 ms of start-up), one
row after the other, so the same ranges and seed always give the same sample. Mimic
followers are never drawn: `values` sets them from their leaders.
"""

from __future__ import annotations

import itertools
import random
from collections.abc import Iterator, Sequence

import numpy as np
from numpy.typing import NDArray

from armcli.robot.joints import Joint, rest
from armcli.robot.model import Robot

GRID_POINTS = 5  # per joint, while the grid has at most MAX_GRID points
MAX_GRID = 125
MAX_CORNERS = 64  # every corner of the range box when there are at most this many
RANDOM_SAMPLES = 100  # draws of `joint_space` (check's and tune's sample)
SAMPLE_SEED = 0
BALANCE_DRAWS = 32  # start points of the balance search (besides rest, poses, corners)
REACH_DRAWS = 500  # the workspace cloud `check` draws (render --reach draws more)

Bounds = Sequence[tuple[float, float]]  # finite (lower, upper) per joint [rad or m]


def bounds(joints: Sequence[Joint]) -> list[tuple[float, float]]:
    """Each joint's finite sampling range (`Joint.span`)."""
    return [j.span for j in joints]


def rest_pose(box: Bounds) -> list[float]:
    """Each joint where it rests (`robot.joints.rest`: 0, else the middle of its range)."""
    return [rest(lo, hi) for lo, hi in box]


def corners(box: Bounds) -> list[list[float]]:
    """Every corner of the box while there are at most MAX_CORNERS, else none."""
    if 2 ** len(box) > MAX_CORNERS:
        return []
    return [list(c) for c in itertools.product(*box)]


def draws(box: Bounds, count: int, seed: int = SAMPLE_SEED) -> list[list[float]]:
    """`count` seeded uniform draws in the box, drawn row after row."""
    return list(iter_draws(box, count, seed))


def iter_draws(box: Bounds, count: int, seed: int = SAMPLE_SEED) -> Iterator[list[float]]:
    """`draws`, one row at a time (for samples too many to hold)."""
    rng = random.Random(seed)
    for _ in range(count):
        yield [rng.uniform(lo, hi) for lo, hi in box]


def grid(box: Bounds) -> list[list[float]] | None:
    """The full grid of GRID_POINTS per joint, or None when it has over MAX_GRID points."""
    if GRID_POINTS ** len(box) > MAX_GRID:
        return None
    axes = [np.linspace(lo, hi, GRID_POINTS) for lo, hi in box]
    return [[float(x) for x in p] for p in itertools.product(*axes)]


def joint_space(box: Bounds) -> NDArray[np.float64]:
    """`check`'s and `tune`'s sample (N, n): the grid, else rest, corners and draws."""
    rows = grid(box)
    if rows is None:
        rows = [rest_pose(box), *corners(box), *draws(box, RANDOM_SAMPLES)]
    return np.array(rows, dtype=float).reshape(len(rows), len(box))


def search_starts(
    box: Bounds, count: int, *, named: Sequence[Sequence[float]] = (), seed: int = SAMPLE_SEED
) -> list[list[float]]:
    """Start points of a search over the box: rest, `named`, corners, then `count` draws."""
    return [rest_pose(box), *[list(r) for r in named], *corners(box), *draws(box, count, seed)]


def values(
    robot: Robot, joints: Sequence[Joint], rows: NDArray[np.float64] | Sequence[Sequence[float]]
) -> list[dict[str, float]]:
    """Each row as joint values by name, with the mimic followers set from their leaders."""
    names = [j.name for j in joints]
    return [robot.follow(dict(zip(names, map(float, r), strict=True))) for r in rows]


def configurations(
    robot: Robot, joints: Sequence[Joint] | None = None
) -> list[tuple[dict[str, float], NDArray[np.float64]]]:
    """`joint_space` over `joints` (default: the leaders), as (values, configuration) pairs."""
    chosen = robot.leaders if joints is None else joints
    rows = joint_space(bounds(chosen))
    return [(v, robot.q(v)) for v in values(robot, chosen, rows)]
