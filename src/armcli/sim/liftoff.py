"""Did the robot tip over in the contact simulation, and which wheel left the ground when?

A robot tips when its base rolls or pitches past its static tipping angle: the
rotation about the nearest support edge that brings its centre of mass over that edge,
atan(d / h) with d the centre of mass's distance inside the edge and h its height
(at the run's start pose), or past TIP_CAP_DEG, whichever is less. Short of that it
rocks back.

A contact link (a wheel, the caster) has lifted off while it carries no normal force
and stands more than LIFT_CLEARANCE above where it started: MuJoCo's soft contacts
let a sliding sphere hop by ~10 µm for a few steps (sim.drivemodel), which is no
lift-off anybody would see. Each lift-off is a warning with its start and duration.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from armcli.analysis.stance import Stance
from armcli.errors import TipOverError

TIP_CAP_DEG = 15.0  # [deg] a base tilted further has tipped whatever its geometry
MIN_BOUND_DEG = 1.0  # [deg] below this the soft contacts' own rocking would count as tipping
LIFT_CLEARANCE = 1e-3  # [m] see the module docstring


@dataclass(frozen=True)
class Lift:
    """One interval during which a contact link was off the ground."""

    link: str
    start: float  # [s]
    duration: float  # [s]
    height: float  # [m] its highest rise above its start

    def line(self) -> str:
        """The warning's text."""
        return (
            f"{self.link} lifts off the ground at t = {self.start:.3f} s for "
            f"{self.duration:.3f} s (up to {self.height * 1e3:.1f} mm)"
        )


@dataclass(frozen=True)
class TipVerdict:
    """The run's tilt against its bound, and its lift-offs."""

    static_angle: float  # [rad] at the start pose (negative: not statically stable)
    direction: str  # toward which edge
    bound: float  # [rad] min(static angle, TIP_CAP_DEG), at least MIN_BOUND_DEG
    max_tilt: float  # [rad]
    max_tilt_time: float  # [s]
    tip_time: float | None  # [s] first state past the bound; None: it did not tip
    lifts: tuple[Lift, ...]

    @property
    def tips(self) -> bool:
        """Whether the base tilted past its bound."""
        return self.tip_time is not None

    def line(self) -> str:
        """The summary's line."""
        head = (
            f"base tilt: max {math.degrees(self.max_tilt):.2f} deg at t = "
            f"{self.max_tilt_time:.3f} s; tips past {math.degrees(self.bound):.1f} deg "
            f"(static tipping angle {math.degrees(self.static_angle):.1f} deg toward "
            f"{self.direction}, cap {TIP_CAP_DEG:g} deg)"
        )
        if self.tips:
            return f"TIPS OVER at t = {self.tip_time:.3f} s: {head}"
        return f"{head}: stays upright; {len(self.lifts)} lift-off(s)"

    def error(self) -> TipOverError:
        """What a run that tipped ends with (after its files are written)."""
        t = float(self.tip_time if self.tip_time is not None else math.nan)
        return TipOverError(
            f"the robot tips over: its base tilted past {math.degrees(self.bound):.1f} deg "
            f"at t = {t:.3f} s (static tipping angle {math.degrees(self.static_angle):.1f} deg "
            f"toward {self.direction})",
            time=t,
            margin=math.nan,
            case="contact simulation",
        )


def static_tipping_angle(stance: Stance, values: Mapping[str, float]) -> tuple[float, str]:
    """[rad] The least rotation about a support edge that puts the centre of mass over it."""
    com = stance.loaded().center_of_mass(stance.q(values))
    h = max(stance.height(com), 1e-9)
    d = stance.polygon.edge_distances(com[:2])
    angles = np.arctan2(d, h)
    i = int(np.argmin(angles))
    return float(angles[i]), stance.polygon.edges[i].direction


def tilt(quat: np.ndarray) -> np.ndarray:
    """[rad] Angle between the base's z axis and the vertical, from (w, x, y, z) rows."""
    x, y = quat[:, 1], quat[:, 2]
    z_z = 1.0 - 2.0 * (x * x + y * y) / np.maximum(np.sum(quat * quat, axis=1), 1e-300)
    return np.asarray(np.arccos(np.clip(z_z, -1.0, 1.0)), dtype=float)


def roll_pitch_yaw(quat: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """[rad] URDF's roll, pitch, yaw (R = Rz Ry Rx) of (w, x, y, z) rows; yaw unwrapped."""
    w, x, y, z = quat.T
    roll = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
    yaw = np.unwrap(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))
    return roll, pitch, yaw


def lifts(link: str, t: np.ndarray, force: np.ndarray, height: np.ndarray) -> list[Lift]:
    """The intervals where `link` carried no force and rose > LIFT_CLEARANCE [m] above its start."""
    rise = height - height[0]
    off = (force <= 0.0) & (rise > LIFT_CLEARANCE)
    edges = np.diff(np.concatenate([[0], off.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    dt = float(t[1] - t[0]) if len(t) > 1 else 0.0
    return [
        Lift(link, float(t[a]), (b - a) * dt, float(np.max(rise[a:b])))
        for a, b in zip(starts, ends, strict=True)
    ]


def verdict(
    stance: Stance,
    start: Mapping[str, float],
    t: np.ndarray,
    quat: np.ndarray,
    contacts: Mapping[str, tuple[np.ndarray, np.ndarray]],
) -> TipVerdict:
    """The verdict of a run: base orientation per state, and per contact link (force, height)."""
    static, direction = static_tipping_angle(stance, start)
    bound = max(min(static, math.radians(TIP_CAP_DEG)), math.radians(MIN_BOUND_DEG))
    angle = tilt(quat)
    k = int(np.argmax(angle))
    past = np.nonzero(angle > bound)[0]
    found = [lift for link, (f, h) in contacts.items() for lift in lifts(link, t, f, h)]
    return TipVerdict(
        static_angle=static,
        direction=direction,
        bound=bound,
        max_tilt=float(angle[k]),
        max_tilt_time=float(t[k]),
        tip_time=float(t[past[0]]) if past.size else None,
        lifts=tuple(sorted(found, key=lambda lift: (lift.start, lift.link))),
    )
