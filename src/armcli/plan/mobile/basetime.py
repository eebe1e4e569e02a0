"""The base path in time: each turn and leg from rest to rest within the wheels' limits.

A turn by theta moves each wheel's rim theta * b/2 (b the wheel separation), a leg of d
moves both d: both are timed on that rim travel with a trapezoidal speed profile within
the rim speed and acceleration limits (`DriveLimits`), and stretched to a whole number of
the diff-drive plugin's update periods so that each period's command belongs to one turn or
one leg. The commands (`commands`) are each period's mean speeds: integrated as an ideal
unicycle, they reach the path's corners and its goal exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from armcli.errors import InputError
from armcli.plan.mobile.basepath import BasePath

DEFAULT_SPEED = 0.3  # [m/s] rim speed when the robot declares no wheel speed limit
TORQUE_SHARE = 0.5  # of the acceleration the wheels' torque could give, when none is declared


@dataclass(frozen=True)
class DriveLimits:
    """What the base may do: rim speed and acceleration, half the track, command period."""

    speed: float  # [m/s]
    accel: float  # [m/s²]
    half_track: float  # [m]
    period: float  # [s] the plugin's update period: one command each
    notes: tuple[str, ...] = ()  # where a limit came from when the robot does not say


@dataclass(frozen=True)
class Motion:
    """One turn in place or one straight leg, from rest to rest."""

    kind: str  # "turn" or "drive"
    pose: tuple[float, float, float]  # where it starts
    amount: float  # [rad] turned, or [m] driven along the heading (negative: reversing)
    t0: float  # [s] when it starts
    duration: float  # [s]
    peak: float  # [rad/s or m/s] the profile's top speed (magnitude)
    accel: float  # [rad/s² or m/s²]

    def travel(self, t: np.ndarray) -> np.ndarray:
        """The signed amount done after t [s] into the motion (trapezoid, clipped)."""
        tt = np.clip(t, 0.0, self.duration)
        ta = self.peak / self.accel
        up = 0.5 * self.accel * np.minimum(tt, ta) ** 2
        cruise = self.peak * np.clip(tt - ta, 0.0, self.duration - 2 * ta)
        late = np.maximum(tt - (self.duration - ta), 0.0)
        down = self.peak * late - 0.5 * self.accel * late**2
        return np.asarray(math.copysign(1.0, self.amount) * (up + cruise + down))

    def pose_at(self, t: np.ndarray) -> np.ndarray:
        """Poses (N, 3) at times t [s] into the motion."""
        s = self.travel(t)
        x, y, yaw = self.pose
        if self.kind == "turn":
            return np.stack([np.full_like(s, x), np.full_like(s, y), yaw + s], axis=1)
        return np.stack([x + s * math.cos(yaw), y + s * math.sin(yaw), np.full_like(s, yaw)], 1)


def profile(amount: float, speed: float, accel: float, period: float) -> tuple[float, float]:
    """(duration [s], peak speed) of a rest-to-rest trapezoid over |amount|.

    The fastest profile within `speed` and `accel`, stretched to whole periods at the same
    acceleration (a lower peak).
    """
    d = abs(amount)
    if d == 0.0:
        return 0.0, 0.0
    t_min = 2 * math.sqrt(d / accel) if d <= speed * speed / accel else d / speed + speed / accel
    t = math.ceil(t_min / period - 1e-9) * period
    peak = 0.5 * (accel * t - math.sqrt(max(accel * accel * t * t - 4 * accel * d, 0.0)))
    return t, peak


@dataclass(frozen=True)
class BaseTiming:
    """The path's motions in order, and what they add up to."""

    motions: tuple[Motion, ...]
    limits: DriveLimits

    @property
    def duration(self) -> float:
        """[s] until the base stands at its goal."""
        return self.motions[-1].t0 + self.motions[-1].duration if self.motions else 0.0

    def pose_at(self, t: np.ndarray) -> np.ndarray:
        """Planned poses (N, 3) at times t [s] (held at the ends)."""
        t = np.asarray(t, dtype=float)
        out = np.empty((len(t), 3))
        if not self.motions:
            return out
        starts = np.array([m.t0 for m in self.motions])
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.motions) - 1)
        for i, m in enumerate(self.motions):
            sel = k == i
            if np.any(sel):
                out[sel] = m.pose_at(t[sel] - m.t0)
        return out

    def commands(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per plugin period: start times [s], linear.x [m/s], angular.z [rad/s] (means)."""
        p = self.limits.period
        n = round(self.duration / p)
        times = np.arange(n) * p
        lin, ang = np.zeros(n), np.zeros(n)
        for m in self.motions:
            k0, k1 = round(m.t0 / p), round((m.t0 + m.duration) / p)
            edges = np.arange(k0, k1 + 1) * p - m.t0
            rate = np.diff(m.travel(edges)) / p
            (ang if m.kind == "turn" else lin)[k0:k1] = rate
        return times, lin, ang


def time_path(path: BasePath, limits: DriveLimits) -> BaseTiming:
    """Each turn and leg of the path timed from rest to rest (see the module docstring)."""
    motions: list[Motion] = []
    t = 0.0
    yaw = path.start[2]
    where = (path.start[0], path.start[1])
    steps: list[tuple[str, float, tuple[float, float]]] = []
    for leg in path.legs:
        steps.append(("turn", float(math.remainder(leg.yaw - yaw, 2 * math.pi)), where))
        steps.append(("drive", leg.sign * leg.length, leg.a))
        yaw, where = leg.yaw, leg.b
    steps.append(("turn", float(math.remainder(path.goal[2] - yaw, 2 * math.pi)), where))
    yaw = path.start[2]
    for kind, amount, (x, y) in steps:
        scale = limits.half_track if kind == "turn" else 1.0  # rim travel per unit
        duration, peak = profile(amount * scale, limits.speed, limits.accel, limits.period)
        if duration == 0.0:
            continue
        motions.append(
            Motion(kind, (x, y, yaw), amount, t, duration, peak / scale, limits.accel / scale)
        )
        t += duration
        if kind == "turn":
            yaw += amount
    return BaseTiming(tuple(motions), limits)


def require_positive(value: float, field: str) -> float:
    """A limit that must be a positive finite number."""
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"must be a positive number, got {value!r}", field=field)
    return value
