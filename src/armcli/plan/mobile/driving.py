"""How much driving a base pose costs from a start: the wheels' travel rotate-drive-rotate.

A differential drive reaches (x, y, yaw) from (x0, y0, yaw0) by turning toward the goal
(or away from it, to reverse), driving straight, and turning to yaw. Each wheel rolls the
distance driven plus, per turn, the angle times half the wheel separation: that sum is the
cost placement minimises (`least driving`), in metres of wheel travel. Vectorised: the
candidates of a placement are scored at once.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

STILL = 1e-9  # [m] a goal this close needs no drive, only a turn
DEFAULT_TURN_RADIUS = 0.25  # [m] half the wheel separation when the robot has no drive


def wrap(angle: np.ndarray) -> np.ndarray:
    """Angles [rad] into [-pi, pi)."""
    turns = np.floor((angle + math.pi) * (0.5 / math.pi))  # floor: cheaper than a float modulo
    return np.asarray(angle - 2.0 * math.pi * turns)


def driving_cost(
    start: ArrayLike, x: np.ndarray, y: np.ndarray, yaw: np.ndarray, turn_radius: float
) -> np.ndarray:
    """Wheel travel [m] from `start` (x, y, yaw) to each (x, y, yaw), forward or reversing."""
    s = np.asarray(start, dtype=float)
    dx, dy = np.asarray(x) - s[0], np.asarray(y) - s[1]
    d = np.hypot(dx, dy)
    heading = np.arctan2(dy, dx)
    turns = []
    for facing in (heading, heading + math.pi):  # drive forward, or reverse
        turns.append(np.abs(wrap(facing - s[2])) + np.abs(wrap(np.asarray(yaw) - facing)))
    turn = np.minimum(turns[0], turns[1])
    in_place = np.abs(wrap(np.asarray(yaw) - s[2]))
    cost: np.ndarray = np.where(d < STILL, turn_radius * in_place, d + turn_radius * turn)
    return cost
