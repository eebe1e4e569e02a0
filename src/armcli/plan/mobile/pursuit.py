"""Following the base plan on the wheels' encoders: rotate to heading, pure pursuit, rotate.

The family Nav2's regulated pure pursuit belongs to, for a path of straight legs with
turns in place: a turn is a proportional turn toward the planned heading, limited by the
wheels' rim speed and acceleration and slowed to arrive (ω ≤ sqrt(2 α |error|)); a leg is
pure pursuit (curvature 2 y / L² toward a point LOOKAHEAD ahead on the leg's line, in the
robot's frame, mirrored when reversing) at a speed regulated down to arrive at the leg's
end (v ≤ sqrt(2 a d) with margin APPROACH). Each motion ends when the odometry says it
is within POSITION_TOL / YAW_TOL of its end. The pose fed back is the plugin's own
encoder odometry (drive.diffdrive), integrated here step by step from the wheel joints'
speeds: every tracking error is corrected, but not what the encoders cannot see. MuJoCo's
drive turns 1.3-3 % less than its encoders say when it turns in place (the caster scrubs,
the soft contacts creep: 20-50 mrad per quarter turn, tests/plan/mobile/test_pursuit.py),
and a metre driven after such a turn is centimetres off. On a robot a localiser removes
that drift (Nav2 follows the path in `map`, AMCL correcting `map -> odom` a few times a
second); `localize` [Hz] stands for one: at that rate the odometry is corrected to the
ground truth (the MCAP's `world -> odom`), in between it runs on the encoders alone.

As a `drive.job.Pilot` it also holds the arm's reference at the planned arrival until the
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
FINAL_FIXES = 3  # localiser fixes at the goal, each followed by a correction if needed
FINAL_TOL = 0.002  # [m] farther than this from the goal after a fix: drive back to it
STILL = 1e-3  # [rad/s] wheels slower than this stand


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

    def __init__(
        self,
        legs: list[Leg],
        motions: tuple[Motion, ...],
        *,
        radius: float,
        separation: float,
        dt: float,
        period: float,
        speed: float,
        accel: float,
        wheel_dof: np.ndarray,
        arrival_step: int,
        axle: np.ndarray,
        localize: float = 0.0,
    ) -> None:
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
        self.axle = np.asarray(axle, dtype=float)  # the wheels' midpoint in the base frame
        self.every = round(1.0 / (localize * dt)) if localize > 0 else 0  # steps per fix
        self.fix = np.zeros(3)  # map -> odom (x, y, yaw): the localiser's last correction
        self.fixes = 0  # fixes taken at the goal
        self.goal = legs[-1]  # the plan's last motion: where the base must end

    @property
    def located(self) -> np.ndarray:
        """The pose followed: the odometry, corrected by the localiser's last fix."""
        x, y, yaw = self.pose
        c, s = math.cos(self.fix[2]), math.sin(self.fix[2])
        return np.array(
            [self.fix[0] + c * x - s * y, self.fix[1] + s * x + c * y, self.fix[2] + yaw]
        )

    def _localize(self, qpos: np.ndarray) -> None:
        """The ground truth's wheels' midpoint, relative to where it started: a perfect fix.

        `qpos`: MuJoCo's free joint (x, y, z, qw, qx, qy, qz) at the time of the fix.
        """
        from armcli.plan.mobile.wheels import to_axle

        w, x, y, z = (float(v) for v in qpos[3:7])
        yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        yaw += 2 * math.pi * round((self.located[2] - yaw) / (2 * math.pi))  # unwrapped
        ax, ay, _ = to_axle((float(qpos[0]), float(qpos[1]), yaw), self.axle)
        truth = np.array([ax - self.axle[0], ay - self.axle[1], yaw])  # the start's at 0
        ox, oy, oyaw = self.pose
        dyaw = truth[2] - oyaw
        c, s = math.cos(dyaw), math.sin(dyaw)
        self.fix = np.array([truth[0] - (c * ox - s * oy), truth[1] - (s * ox + c * oy), dyaw])

    def arm_steps(self, k0: int, k1: int) -> np.ndarray:
        """The arm's reference step at steps k0 .. k1 - 1 (held until the base has arrived).

        Held at the planned arrival until the follower has the base standing at its goal,
        then resumed from there.
        """
        k = np.arange(k0, k1)
        if self.arrived is None:
            return np.minimum(k, self.arrival_step)
        return np.minimum(self.arrival_step + (k - self.arrived), k)

    def observe(self, k0: int, seen: np.ndarray) -> None:
        """Integrate the encoder odometry over steps k0 .. k0 + len(seen) - 1, with the fixes.

        Step k's wheel speeds (seen[:, 7:9], the state it started from) move the pose by
        one step, as the plugin's odometry does; a fix (every `every` steps) sees the pose
        after its step. Plain floats: a plugin period is ~20 steps, too few for numpy.
        """
        r, dt, b = self.r, self.dt, self.b
        x, y, yaw = (float(v) for v in self.pose)
        for i, (vl, vr) in enumerate(seen[:, 7:9].tolist()):
            wl, wr = vl * r * dt, vr * r * dt
            dtheta = (wr - wl) / b
            heading = yaw + dtheta / 2.0
            x += (wl + wr) / 2 * math.cos(heading)
            y += (wl + wr) / 2 * math.sin(heading)
            yaw += dtheta
            if self.every and (k0 + i) % self.every == 0:
                self.pose = np.array([x, y, yaw])
                self._localize(seen[i, :7])
        self.pose = np.array([x, y, yaw])
        self.k = k0 + len(seen) - 1

    def command(self, t: float, data: Any) -> tuple[float, float]:
        """The twist for the next plugin period.

        With a localiser, the last leg and turn are checked again after a fix taken once the
        base stands (up to FINAL_FIXES times) before the base counts as arrived.
        """
        while self.i < len(self.legs):
            leg = self.legs[self.i]
            out = self._turn(leg) if leg.kind == "turn" else self._drive(leg)
            if out is not None:
                self.v, self.w = out
                return out
            self.i += 1
        self.v = self.w = 0.0
        if self.arrived is None:
            if np.any(np.abs(data.qvel[self.wheel_dof]) > STILL):
                return 0.0, 0.0  # wait until the wheels stand
            if self.every and self.fixes < FINAL_FIXES:
                self.fixes += 1
                self._localize(data.qpos)
                if self._correct():
                    return self.command(t, data)
            self.arrived = self.k
        return 0.0, 0.0

    def _correct(self) -> bool:
        """After a fix at the goal: drive along the heading to the goal's nearest, turn to it.

        The base cannot step sideways: a sideways error would need turns whose own creep
        moves it again (and room beside the objects it parks at). The plan arrives heading
        the goal's way (`plan.mobile.basepath` weighs turns so), so what is left to correct
        is along the heading, and the yaw.
        """
        goal = self.goal
        end = goal.b if goal.kind == "drive" else goal.a
        here = self.located
        heading = np.array([math.cos(here[2]), math.sin(here[2])])
        along = float((end - here[:2]) @ heading)
        if abs(along) < FINAL_TOL and abs(goal.yaw - here[2]) < YAW_TOL:
            return False
        if abs(along) >= FINAL_TOL:
            b = here[:2] + along * heading
            self.legs.append(
                Leg("drive", here[:2].copy(), b, float(here[2]), math.copysign(1.0, along))
            )
        self.legs.append(Leg("turn", end.copy(), end.copy(), goal.yaw, 1.0))
        return True

    def _ramp(self, want: float, last: float, accel: float) -> float:
        step = accel * self.period
        return min(max(want, last - step), last + step)

    def _turn(self, leg: Leg) -> tuple[float, float] | None:
        err = leg.yaw - self.located[2]
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
        here = self.located
        pos = here[:2]
        remaining = length - float((pos - leg.a) @ u)
        if remaining < POSITION_TOL:
            return None
        ahead = leg.a + u * (length - remaining + LOOKAHEAD)  # on the leg's line
        facing = here[2] + (math.pi if leg.sign < 0 else 0.0)
        c, s = math.cos(facing), math.sin(facing)
        dx, dy = ahead - pos
        lx, ly = c * dx + s * dy, -s * dx + c * dy
        curvature = 2.0 * ly / max(lx * lx + ly * ly, 1e-12)
        want = min(self.speed, math.sqrt(2 * APPROACH * self.accel * remaining))
        want = max(want, MIN_SPEED)
        want /= 1.0 + abs(curvature) * self.b / 2  # the outer wheel within the rim speed
        v = self._ramp(leg.sign * want, self.v, self.accel)
        return v, abs(v) * curvature  # reversing: the mirrored frame turns the same way
