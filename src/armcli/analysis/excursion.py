"""When does a zero-moment point outside the support polygon tip the robot over?

Outside by e, the ground cannot supply the moment the motion needs: the robot starts to
rotate about that support edge and gains the angular velocity m g ∫ e dt / I_edge. Once
the point is back inside, gravity brings it back unless that rotation carries its centre
of mass over the edge. So each interval the point spends outside (an excursion) either
tips the robot or only lifts a wheel for that long (docs/check.md derives the bound).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from armcli.analysis import zmp as zmps
from armcli.analysis.stance import Stance

G = 9.81  # [m/s²] Pinocchio's gravity


@dataclass(frozen=True)
class Excursion:
    """One interval during which the zero-moment point of one case stays outside the polygon.

    `impulse` = ∫ e dt [m·s], e the distance outside; the robot turns about the edge by
    the angular velocity m g impulse / I_edge, and tips when that carries its centre of
    mass over the edge: impulse >= `bound` = sqrt(2 I_edge m g (sqrt(d² + h²) - h)) / (m g),
    d, h the centre of mass's distance inside the edge and height (docs/check.md).
    """

    case: str
    start: float  # [s]
    duration: float  # [s]
    depth: float  # [m] the farthest outside
    direction: str  # toward which edge
    impulse: float  # [m·s]
    bound: float  # [m·s]; 0: the centre of mass itself is past the edge

    @property
    def tips(self) -> bool:
        """Whether it rotates the robot over the edge."""
        return self.impulse >= self.bound

    def line(self) -> str:
        """The lift-off warning of an excursion that does not tip the robot."""
        share = f"{100 * self.impulse / self.bound:.2g} %" if self.bound > 0 else "all"
        return (
            f"the zero-moment point leaves the support polygon toward {self.direction} at "
            f"t = {self.start:.3f} s for {self.duration:.3f} s ({self.case}, up to "
            f"{self.depth * 1e3:.1f} mm): a wheel lifts off for that long, the robot does not "
            f"tip (its turning impulse is {share} of what tips it, docs/check.md)"
        )


def excursions(stance: Stance, series: zmps.ZmpSeries) -> tuple[Excursion, ...]:
    """Every interval of every case with the point outside, and whether it tips the robot."""
    cases = 1 if series.base_accel == 0 else len(zmps.CASES)
    out = []
    for c in range(cases):
        outside = series.margin[:, c] < 0
        edges = np.diff(np.concatenate([[0], outside.astype(np.int8), [0]]))
        for a, b in zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0], strict=True):
            out.append(_excursion(stance, series, c, int(a), int(b)))
    return tuple(sorted(out, key=lambda e: (e.start, e.case)))


def _excursion(stance: Stance, series: zmps.ZmpSeries, c: int, a: int, b: int) -> Excursion:
    """Rows a..b-1 of case c are outside; the neighbours bound the interval (e = 0 there)."""
    lo, hi = max(a - 1, 0), min(b, len(series.t) - 1)
    t = series.t[lo : hi + 1]
    e = np.clip(-series.margin[lo : hi + 1, c], 0.0, None)
    e = np.where(np.isfinite(e), e, 0.0)  # f_z <= 0 (no point): counted by its neighbours
    impulse = float(np.sum(0.5 * (e[1:] + e[:-1]) * np.diff(t))) if len(t) > 1 else 0.0
    k = a + int(np.argmax(np.nan_to_num(-series.margin[a:b, c], posinf=1e9)))
    p = series.zmp[k, c]
    poly = stance.polygon
    edge = poly.nearest_edge(p) if np.all(np.isfinite(p)) else 0
    com, inertia = series.bodies.get(k, (np.zeros(3), np.zeros((3, 3))))
    mass = stance.loaded().mass
    d = float(poly.edge_distances(com[:2])[edge])
    h = stance.height(com)
    ex = poly.edges[edge]
    u = np.array([ex.b[0] - ex.a[0], ex.b[1] - ex.a[1], 0.0])
    u /= max(float(np.linalg.norm(u)), 1e-12)
    i_edge = float(u @ inertia @ u) + mass * (d * d + h * h)
    barrier = mass * G * (math.hypot(d, h) - h) if d > 0 else 0.0
    depth = float(np.max(np.where(np.isfinite(e), e, 0.0)))
    return Excursion(
        case=zmps.CASES[c],
        start=float(series.t[a]),
        duration=float(series.t[b - 1] - series.t[a]) + _dt(series),
        depth=depth,
        direction=ex.direction,
        impulse=impulse,
        bound=math.sqrt(2.0 * i_edge * barrier) / (mass * G),
    )


def _dt(series: zmps.ZmpSeries) -> float:
    """[s] the time of one kept state (the smallest spacing of the series)."""
    return float(np.min(np.diff(series.t))) if len(series.t) > 1 else 0.0
