"""A plan's motion is bounded in time before it is timed and sampled (issue 42).

`limit.acceleration: 1e-9` (spec or URDF 1.2) or `limit.velocity: 1e-6` made `plan` time a
motion of days and sample it at 100 Hz: minutes of CPU, 2.7-2.9 GB and a MemoryError for
a 107-million-row array. No joint can go from rest to rest over a distance d faster than
with its own velocity and acceleration limits alone: t = d/v + v/a when it reaches v
(d >= v²/a), else 2·sqrt(d/a). A path of straight segments timed from rest to rest
(plan.timing) takes at least the sum over segments of the slowest joint's time, so a
motion whose bound passes MAX_MOTION_S is refused before TOPP-RA runs, naming the joint
and the limit that make it so; the timed duration is checked again before sampling.
"""

from __future__ import annotations

import numpy as np

from armcli.errors import InputError, split_source
from armcli.plan.robot import PlanRobot

MAX_MOTION_S = 3600.0  # [s] the longest motion a plan may have (an hour)


def joint_times(d: np.ndarray, v: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's shortest rest-to-rest time over distances `d` [s], and its velocity part.

    `v`, `a` may be inf (no limit). The velocity part is d/v of a move that reaches v.
    """
    d = np.abs(d)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        reaches = d * a >= v * v  # cruises at v (False when v is inf)
        cruise = np.where(reaches, d / v + v / a, 0.0)
        ramp = np.where(reaches, 0.0, 2.0 * np.sqrt(d / a))
        by_velocity = np.where(reaches, d / v, 0.0)
    return np.nan_to_num(cruise + ramp, nan=0.0), np.nan_to_num(by_velocity, nan=0.0)


def check_motion_time(robot: PlanRobot, path: np.ndarray) -> None:
    """Refuse a polyline whose rest-to-rest motion must last longer than MAX_MOTION_S."""
    steps = np.diff(np.asarray(path, dtype=float), axis=0)
    total, slowest = 0.0, np.zeros(len(robot.joints))
    velocity_part = np.zeros(len(robot.joints))
    for d in steps:
        t, tv = joint_times(d, robot.velocity, robot.acceleration)
        total += float(np.max(t, initial=0.0))
        slowest += t
        velocity_part += tv
    if total <= MAX_MOTION_S:
        return
    k = int(np.argmax(slowest))
    by_velocity = velocity_part[k] >= 0.5 * slowest[k]
    kind = "velocity" if by_velocity else "acceleration"
    value = robot.velocity[k] if by_velocity else robot.acceleration[k]
    prismatic = any(j.name == robot.joints[k] and j.type == "prismatic" for j in robot.urdf.joints)
    unit = ("m" if prismatic else "rad") + ("/s" if by_velocity else "/s²")
    raise InputError(
        f"joint {robot.joints[k]}: limit.{kind} {value:g} {unit} makes this motion last at "
        f"least {total:.3g} s, more than the {MAX_MOTION_S:g} s a plan may take; not planned",
        file=split_source(robot.urdf.source)[0],
    )


def check_duration(duration: float) -> None:
    """Refuse a timed motion longer than MAX_MOTION_S before it is sampled."""
    if not duration <= MAX_MOTION_S:
        raise InputError(
            f"the timed motion lasts {duration:.3g} s, more than the {MAX_MOTION_S:g} s a plan "
            "may take (velocity, acceleration or effort limits too low); not sampled",
            field="plan",
        )
