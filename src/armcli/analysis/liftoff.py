"""Did the robot tip over in the contact simulation, and which wheel left the ground when?

Each edge of the support polygon is a tipping axis with its own static tipping angle:
the rotation about that edge that brings the centre of mass over it, atan(d / h) with d
the centre of mass's distance inside the edge and h its height (at the run's start pose;
at least MIN_BOUND_DEG). The base's tilt toward an edge is the rotation about that edge's
axis that gravity, seen from the base, shows (`edge_tilts`); a robot that tips backward
is measured against its rear edge's angle, not against the least angle of all edges.

Past an edge's angle the robot may still rock back onto its contacts: the arm swinging
in, the wheels' reaction easing after a launch. So a run tips over only when it ends
past an edge's angle, or tilted more than TIP_CAP_DEG (resting on something other than
its contacts); it tipped when that last excursion began. Excursions it came back from
are reported (`Rock`), as are lift-offs.

A contact link (a wheel, the caster) has lifted off while it carries no normal force
and stands more than LIFT_CLEARANCE above where it started: MuJoCo's soft contacts
let a sliding sphere hop by ~10 µm for a few steps (drive.model), which is no
lift-off anybody would see. Each lift-off is a warning with its start and duration.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from armcli.analysis.stance import Stance
from armcli.errors import TipOverError
from armcli.robot.frames import tilt

TIP_CAP_DEG = 15.0  # [deg] a base that ends the run tilted further has fallen
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
class Rock:
    """An excursion past an edge's tipping angle that came back onto the contacts."""

    direction: str  # toward which edge
    angle: float  # [rad] that edge's tipping angle
    start: float  # [s]
    duration: float  # [s]
    peak: float  # [rad] the largest tilt toward the edge

    def line(self) -> str:
        """The warning's text."""
        return (
            f"the base rocked past its {self.direction} tipping angle "
            f"({math.degrees(self.angle):.1f} deg) at t = {self.start:.3f} s for "
            f"{self.duration:.3f} s (up to {math.degrees(self.peak):.1f} deg) and came back "
            "onto its contacts"
        )


@dataclass(frozen=True)
class TiltVerdict:
    """The run's tilt toward each support edge against that edge's angle, and its lift-offs.

    The drive's `TipVerdict` (analysis.tipverdict), as `ZmpReport` is the fixed-base run's.
    """

    angles: tuple[float, ...]  # [rad] per edge: static tipping angle, at least MIN_BOUND_DEG
    directions: tuple[str, ...]  # per edge
    max_tilt: float  # [rad] the base's largest tilt, in any direction
    max_tilt_time: float  # [s]
    worst: int  # the edge tilted toward most, relative to its angle
    worst_tilt: float  # [rad] the largest tilt toward that edge
    tip_time: float | None  # [s] when the excursion it did not come back from began
    rocks: tuple[Rock, ...]
    lifts: tuple[Lift, ...]

    @property
    def tips(self) -> bool:
        """Whether the run ended past an edge's tipping angle (or past TIP_CAP_DEG)."""
        return self.tip_time is not None

    @property
    def static_angle(self) -> float:
        """[rad] the least tipping angle over the edges (negative: not statically stable)."""
        return min(self.angles)

    @property
    def direction(self) -> str:
        """Toward which edge the base tilted most, relative to that edge's angle."""
        return self.directions[self.worst]

    def line(self) -> str:
        """The summary's line."""
        head = (
            f"base tilt: max {math.degrees(self.max_tilt):.2f} deg at t = "
            f"{self.max_tilt_time:.3f} s; toward {self.direction} up to "
            f"{math.degrees(self.worst_tilt):.1f} deg of its "
            f"{math.degrees(self.angles[self.worst]):.1f} deg tipping angle"
        )
        if self.tips:
            return f"TIPS OVER at t = {self.tip_time:.3f} s: {head}, and did not come back"
        return f"{head}: stays upright; {len(self.lifts)} lift-off(s)"

    def notes(self) -> list[str]:
        """Warnings: each lift-off and each excursion past a tipping angle, in time order."""
        events = [(r.start, r.line()) for r in self.rocks]
        events += [(lift.start, lift.line()) for lift in self.lifts]
        return [text for _, text in sorted(events)]

    def error(self) -> TipOverError:
        """What a run that tipped ends with (after its files are written)."""
        t = float(self.tip_time if self.tip_time is not None else math.nan)
        return TipOverError(
            f"the robot tips over: its base tilted toward {self.direction} past that edge's "
            f"tipping angle ({math.degrees(self.angles[self.worst]):.1f} deg) at t = "
            f"{t:.3f} s and did not come back",
            time=t,
            margin=math.nan,
            case="contact simulation",
        )


def tipping_angles(stance: Stance, values: Mapping[str, float]) -> np.ndarray:
    """[rad] per support edge: the rotation about it that puts the centre of mass over it."""
    com = stance.loaded().center_of_mass(stance.q(values))
    h = max(stance.height(com), 1e-9)
    return np.asarray(np.arctan2(stance.polygon.edge_distances(com[:2]), h), dtype=float)


def static_tipping_angle(stance: Stance, values: Mapping[str, float]) -> tuple[float, str]:
    """[rad] The least rotation about a support edge that puts the centre of mass over it."""
    angles = tipping_angles(stance, values)
    i = int(np.argmin(angles))
    return float(angles[i]), stance.polygon.edges[i].direction


def edge_tilts(quat: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """[rad] (N, k): per (w, x, y, z) row, the base's tilt toward each outward `normals` row.

    The world's up axis seen in the base frame is u (the third row of R); the base has
    rotated by atan2(-u · n, u_z) about the edge whose outward normal is n (root x-y).
    """
    w, x, y, z = (quat / np.linalg.norm(quat, axis=1, keepdims=True)).T
    ux, uy, uz = 2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)
    lean = -(np.outer(ux, normals[:, 0]) + np.outer(uy, normals[:, 1]))
    return np.asarray(np.arctan2(lean, uz[:, None]), dtype=float)


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


def intervals(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, past-the-last) index of each run of True in `mask`."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    return [(int(a), int(b)) for a, b in zip(starts, ends, strict=True)]


def verdict(
    stance: Stance,
    start: Mapping[str, float],
    t: np.ndarray,
    quat: np.ndarray,
    contacts: Mapping[str, tuple[np.ndarray, np.ndarray]],
) -> TiltVerdict:
    """The verdict of a run: base orientation per state, and per contact link (force, height)."""
    angles = np.maximum(tipping_angles(stance, start), math.radians(MIN_BOUND_DEG))
    toward = edge_tilts(quat, stance.polygon.normals)
    past = toward > angles
    angle = tilt(quat)
    down = past.any(axis=1) | (angle > math.radians(TIP_CAP_DEG))
    last = intervals(down)[-1] if down[-1] else None
    rocks = [
        Rock(
            stance.polygon.edges[i].direction,
            float(angles[i]),
            float(t[a]),
            float(t[min(b, len(t) - 1)] - t[a]),
            float(np.max(toward[a:b, i])),
        )
        for i in range(len(angles))
        for a, b in intervals(past[:, i])
        if last is None or a < last[0]
    ]
    ratio = toward / angles
    worst = int(np.argmax(ratio)) % ratio.shape[1]
    if last is not None:
        worst = int(np.argmax(toward[-1] - angles))
    found = [lift for link, (f, h) in contacts.items() for lift in lifts(link, t, f, h)]
    m = int(np.argmax(angle))
    return TiltVerdict(
        angles=tuple(float(a) for a in angles),
        directions=tuple(e.direction for e in stance.polygon.edges),
        max_tilt=float(angle[m]),
        max_tilt_time=float(t[m]),
        worst=int(worst),
        worst_tilt=float(np.max(toward[:, worst])),
        tip_time=float(t[last[0]]) if last is not None else None,
        rocks=tuple(sorted(rocks, key=lambda r: (r.start, r.direction))),
        lifts=tuple(sorted(found, key=lambda lift: (lift.start, lift.link))),
    )
