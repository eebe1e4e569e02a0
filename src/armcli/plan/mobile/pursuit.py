"""Following the base plan on the wheels' encoders: rotate to heading, pure pursuit, rotate.

The family Nav2's regulated pure pursuit belongs to, for a path of straight legs with
turns in place: a turn is a proportional turn toward the planned heading, limited by the
wheels' rim speed and acceleration and slowed to arrive (ω ≤ sqrt(2 α |error|)); a leg is
pure pursuit (curvature 2 y / L² toward a point LOOKAHEAD ahead on the leg's line, in the
robot's frame, mirrored when reversing) at a speed regulated down to arrive at the leg's
end (v ≤ sqrt(2 a d) with margin APPROACH). Each motion ends when the odometry says it
is within POSITION_TOL / YAW_TOL of its end. The pose fed back is the plugin's own
encoder odometry (sim.diffdrive), integrated here step by step from the wheel joints'
speeds, so wheel slip is not seen (as on the robot) but every tracking error is corrected.

As a `sim.drive.Pilot` it also holds the arm's reference at the planned arrival until the
base has actually arrived: the arm moves only once the base stands.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.plan.mobile.basetime import BaseTiming, Motion

LOOKAHEAD = 0.25  # [m] pure pursuit's lookahead distance along the leg
APPROACH = 0.5  # share of the acceleration limit used to slow down to each motion's end
POSITION_TOL = 0.001  # [m] a leg ends this near its end (along the leg)
YAW_TOL = 0.001  # [rad] a turn ends this near its heading
MIN_SPEED = 0.01  # [m/s] the rim speed kept until a motion ends (no endless crawl)
TURN_GAIN = 4.0  # [1/s] proportional gain of a turn (below the slow-down's cap)


@dataclass(frozen=True)
class Leg:
    """One motion of the plan in the odometry frame: a turn to `yaw`, or a leg a -> b."""

    kind: str
    a: np.ndarray  # (2,) [m]
    b: np.ndarray
    yaw: float  # [rad] unwrapped: the heading to hold (a leg) or to reach (a turn)
    sign: float  # +1 forward, -1 reversing


def legs_in_odom(timing: BaseTiming, start: tuple[float, float, float]) -> list[Leg]:
    """The plan's motions in the odometry frame: the start pose at the origin, yaw 0."""
    c, s = math.cos(start[2]), math.sin(start[2])

    def local(x: float, y: float) -> np.ndarray:
        dx, dy = x - start[0], y - start[1]
        return np.array([c * dx + s * dy, -s * dx + c * dy])

    out = []
    for m in timing.motions:
        x, y, yaw = m.pose
        a = local(x, y)
        rel = yaw - start[2]  # BaseTiming accumulates yaw: unwrapped from the start's
        if m.kind == "turn":
            out.append(Leg("turn", a, a, rel + m.amount, 1.0))
        else:
            b = a + m.amount * np.array([math.cos(rel), math.sin(rel)])
            out.append(Leg("drive", a, b, rel, math.copysign(1.0, m.amount)))
    return out


class Pursuit:
    """The pilot: odometry, the motion being followed, the commands, the arm's hold."""

    def __init__(self, legs: list[Leg], motions: tuple[Motion, ...], *, radius: float,
                 separation: float, dt: float, period: float, speed: float, accel: float,
                 wheel_dof: np.ndarray, arrival_step: int) -> None:  # fmt: skip
        self.legs, self.motions = legs, motions
        self.r, self.b, self.dt, self.period = radius, separation, dt, period
        self.speed, self.accel = speed, accel
        self.wheel_dof = wheel_dof
        self.arrival_step = arrival_step  # when the plan has the base arrive
        self.pose = np.zeros(3)  # encoder odometry (x, y, unwrapped yaw)
        self.i = 0  # the leg being followed
        self.v = self.w = 0.0  # last commanded
        self.arrived: int | None = None  # the step the base arrived at
        self.k = 0

    def arm_step(self, k: int, data: Any) -> int:
        """Integrate the odometry over step k; the arm's reference step (held until arrival)."""
        wl, wr = (float(x) * self.r * self.dt for x in data.qvel[self.wheel_dof])
        dtheta = (wr - wl) / self.b
        heading = self.pose[2] + dtheta / 2.0
        self.pose += ((wl + wr) / 2 * math.cos(heading), (wl + wr) / 2 * math.sin(heading), dtheta)
        self.k = k
        if self.arrived is None:
            return min(k, self.arrival_step)
        return min(self.arrival_step + (k - self.arrived), k)

    def command(self, t: float, data: Any) -> tuple[float, float]:
        """The twist for the next plugin period."""
        while self.i < len(self.legs):
            leg = self.legs[self.i]
            out = self._turn(leg) if leg.kind == "turn" else self._drive(leg)
            if out is not None:
                self.v, self.w = out
                return out
            self.i += 1
        if self.arrived is None:
            self.arrived = self.k
        self.v = self.w = 0.0
        return 0.0, 0.0

    def _ramp(self, want: float, last: float, accel: float) -> float:
        step = accel * self.period
        return min(max(want, last - step), last + step)

    def _turn(self, leg: Leg) -> tuple[float, float] | None:
        err = leg.yaw - self.pose[2]
        if abs(err) < YAW_TOL:
            return None
        half = self.b / 2
        w_max, alpha = self.speed / half, APPROACH * self.accel / half
        want = min(w_max, math.sqrt(2 * alpha * abs(err)), TURN_GAIN * abs(err))
        want = max(want, MIN_SPEED / half)
        return 0.0, self._ramp(math.copysign(want, err), self.w, self.accel / half)

    def _drive(self, leg: Leg) -> tuple[float, float] | None:
        d = leg.b - leg.a
        length = float(np.hypot(*d))
        u = d / max(length, 1e-12)
        pos = self.pose[:2]
        remaining = length - float((pos - leg.a) @ u)
        if remaining < POSITION_TOL:
            return None
        ahead = leg.a + u * (length - remaining + LOOKAHEAD)  # on the leg's line
        facing = self.pose[2] + (math.pi if leg.sign < 0 else 0.0)
        c, s = math.cos(facing), math.sin(facing)
        dx, dy = ahead - pos
        lx, ly = c * dx + s * dy, -s * dx + c * dy
        curvature = 2.0 * ly / max(lx * lx + ly * ly, 1e-12)
        want = min(self.speed, math.sqrt(2 * APPROACH * self.accel * remaining))
        want = max(want, MIN_SPEED)
        want /= 1.0 + abs(curvature) * self.b / 2  # the outer wheel within the rim speed
        v = self._ramp(leg.sign * want, self.v, self.accel)
        return v, abs(v) * curvature  # reversing: the mirrored frame turns the same way
