"""Static balance: the whole robot's centre of mass over its support polygon.

Model: rigid bodies on rigid, flat, level ground, contacts that neither slip nor lift,
and no motion (velocities and accelerations are `simulate`'s zero-moment point). The
centre of mass (Pinocchio, payload included as a point mass) projects vertically onto
the ground; its margin toward an edge of the support polygon (`analysis.support`) is its
distance to that edge's line, positive inside. On a slope rising at theta toward an edge,
gravity leans by theta in the robot's frame and the projection moves h tan(theta)
toward that edge (h: the centre of mass's height above the ground), so the robot tips
at the slope angle atan(d / h): the tipping angle of that direction.

The worst over the joint range is found by search, per edge and per measure (margin,
tipping angle): every seed (the zero pose, the named poses, every corner of the range
box when there are at most 64, and seeded uniform draws) is evaluated, and a projected
gradient descent (`analysis.boxsearch`, with Pinocchio's centre-of-mass Jacobian as the
gradient) runs from the best three within the joint limits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.analysis.boxsearch import minimize_box
from armcli.analysis.stance import Stance
from armcli.robot import sampling
from armcli.robot.sampling import BALANCE_DRAWS

SEEDS_DESCENDED = 3  # local searches per edge and measure, from the best seeds
# The search is bounded (issue 31: TIAGo dual, 25 joints on a 37-edge round base, took
# 307,000 Jacobians and 12 CPU s; nearly every descent ran its 200 iterations along a flat
# tail). Each descent gets DESCENT_ITERATIONS (on TIAGo the least margin and tipping angle
# come out the same to 0.1 mm and 0.1 mrad, the payload within 0.02 kg; the course robot's
# descents end sooner), starts from the neighbouring edge's or the previous payload's
# optimum, and one analysis spends at most MAX_JACOBIANS: past it the descents stop where
# they are (a zero gradient ends them), each result still a real configuration.
DESCENT_ITERATIONS = 50
MAX_JACOBIANS = 100_000
PAYLOAD_ROUNDS = 8  # fixed-point rounds for the largest payload over the range
PAYLOAD_TOL = 1e-6  # [m] slack below which a payload still counts as holding
MAX_PAYLOAD = 1e4  # [kg] beyond this the payload "holds" anything: reported as inf
WORST = "worst over the joint range"


@dataclass(frozen=True)
class PoseBalance:
    """The centre of mass at one configuration, against every edge of the polygon."""

    name: str  # a named pose, or WORST (toward one direction)
    q: tuple[tuple[str, float], ...]  # [rad or m]
    com: tuple[float, float, float]  # [m] root frame, payload included
    margins: tuple[float, ...]  # [m] signed distance to each edge's line (+ inside)
    tip_angles: tuple[float, ...]  # [rad] slope that tips it over each edge
    margin: float  # [m] signed distance to the polygon (negative: that far outside)
    payload_max: float | None  # [kg] at the payload point with margin >= the threshold

    @property
    def edge(self) -> int:
        """The edge with the least margin."""
        return int(np.argmin(self.margins))


@dataclass(frozen=True)
class StaticBalance:
    """The static balance of one robot: polygon, named poses, worst over the joint range."""

    contacts: tuple[str, ...]
    polygon: tuple[tuple[float, float], ...]  # [m] counter-clockwise, root x-y plane
    directions: tuple[str, ...]  # each edge's outward compass direction
    headings: tuple[float, ...]  # [rad] each edge's outward normal
    ground: float  # [m] the ground plane's height in the root frame
    mass: float  # [kg] robot without payload
    payload: str | None  # "2 kg at hand_link + (0, 0, 0.3)"
    payload_point: str  # where the payload (or a suggested one) hangs
    threshold: float  # [m] margin below which `support-margin` warns
    poses: tuple[PoseBalance, ...]
    worst: tuple[PoseBalance, ...]  # per edge: the configuration closest to tipping over it
    worst_tip_angles: tuple[float, ...]  # [rad] per edge: smallest tipping angle over the range
    payload_max: float | None  # [kg] the most that holds at every named pose and over the range
    contact_tol: float | None = None  # [m] how the contacts were found; None: user-named

    @property
    def worst_overall(self) -> PoseBalance:
        """The configuration of the joint range with the least margin."""
        return min(self.worst, key=lambda p: p.margins[p.edge])


class _Mass:
    """Centre of mass and its Jacobian over the searched joints, with a payload of mass m."""

    def __init__(self, stance: Stance) -> None:

        self.s = stance
        self.robot = stance.robot
        self.M = stance.mass
        self.iv = [jr.idx_v for jr in stance.joints]
        self.payload = stance.payload  # its link is one of the robot's (stance_of checked)
        self.jacobians = 0  # com_jac calls so far (bounded by MAX_JACOBIANS)

    @property
    def spent(self) -> bool:
        """The search budget is used up: descents stop where they are."""
        return self.jacobians >= MAX_JACOBIANS

    def q(self, x: ArrayLike) -> NDArray[np.float64]:
        return self.s.q(x)

    def parts(self, x: ArrayLike) -> tuple[NDArray[Any], NDArray[Any]]:
        """(unloaded centre of mass, payload point) [m] at joint values x."""
        return self.parts_at(self.q(x))

    def parts_at(self, q: NDArray[np.float64]) -> tuple[NDArray[Any], NDArray[Any]]:
        """(unloaded centre of mass, payload point) [m] at the configuration q."""
        c0 = self.robot.center_of_mass(q)
        if self.payload is None:
            return c0, c0
        return c0, self.robot.point_position(self.payload.link, self.payload.xyz, q)

    def com(self, x: ArrayLike, m: float) -> NDArray[Any]:
        c0, p = self.parts(x)
        return (self.M * c0 + m * p) / (self.M + m)

    def com_jac(self, x: ArrayLike, m: float) -> tuple[NDArray[Any], NDArray[Any]]:
        """Centre of mass [m] and d com / dx (3, n); d com / dx is zero once `spent`."""
        self.jacobians += 1
        c, J = self._com_jac(x, m)
        return c, (0.0 * J if self.spent else J)

    def _com_jac(self, x: ArrayLike, m: float) -> tuple[NDArray[Any], NDArray[Any]]:
        q = self.q(x)
        c0, J0 = self.robot.center_of_mass_jacobian(q)
        J0 = J0[:, self.iv]
        if self.payload is None or m <= 0:
            return c0, J0
        p, Jp = self.robot.jacobian(q, self.payload.link, self.payload.xyz, self.iv)
        Jp = Jp[:3]
        return (self.M * c0 + m * p) / (self.M + m), (self.M * J0 + m * Jp) / (self.M + m)


def analyse(
    stance: Stance, poses: Sequence[tuple[str, dict[str, float]]], threshold: float
) -> StaticBalance:
    """Margins and tipping angles at `poses` and over the joint range, largest payload."""
    ev = _Mass(stance)
    m = stance.payload.mass if stance.payload is not None else 0.0
    poly = stance.polygon
    named = tuple(_at(ev, name, _values(stance, v), m, threshold) for name, v in poses)
    seeds = _seeds(stance, [_values(stance, v) for _, v in poses])
    worst, tips = _search(ev, seeds, m, threshold)
    best = [p.payload_max for p in named]
    best.append(_payload_over_range(ev, seeds, m, threshold))
    known = [b for b in best if b is not None]
    edges = poly.edges
    return StaticBalance(
        contacts=stance.ground.links,
        polygon=poly.vertices,
        directions=tuple(e.direction for e in edges),
        headings=tuple(e.angle for e in edges),
        ground=stance.ground.height,
        mass=stance.mass,
        payload=stance.payload.label if stance.payload is not None and m > 0 else None,
        payload_point=_point_label(stance),
        threshold=threshold,
        poses=named,
        worst=worst,
        worst_tip_angles=tips,
        payload_max=min(known) if len(known) == len(best) else None,
        contact_tol=None if stance.ground.declared else stance.ground.tol,
    )


class MarginAt:
    """The static tip-over margin [m] as a function of some joints' values: built once per robot.

    The signed distance of the centre of mass (payload included) to the support polygon's
    boundary, as `analyse` reports it per pose, with `joints` at the values given and the
    other searched joints at zero (clamped into range): what a base placement must keep
    positive at every pose it judges.
    """

    def __init__(self, stance: Stance, joints: Sequence[str]) -> None:
        """`joints`: the names the values of each call are given for, in order."""
        self.ev = _Mass(stance)
        self.m = stance.payload.mass if stance.payload is not None else 0.0
        searched = {
            j.name: (j, lo, hi) for j, (lo, hi) in zip(stance.joints, stance.box, strict=True)
        }
        self.template = stance.q(_values(stance, {}))
        # (value index, q index, lower, upper) per given joint the search moves; a continuous
        # one is stored as (cos, sin): through Stance.q, the one place that writes it
        self.slots = [
            (k, *searched[n][1:], searched[n][0]) for k, n in enumerate(joints) if n in searched
        ]
        self.fast = all(not j.continuous for *_, j in self.slots)
        self.polygon = stance.polygon

    def __call__(self, values: ArrayLike) -> float:
        """The margin [m] with the joints at `values` [rad or m]."""
        return self.polygon.margin(self.com(values))

    def com(self, values: ArrayLike) -> NDArray[np.float64]:
        """The centre of mass [m] (payload included) with the joints at `values`."""
        given = np.asarray(values, dtype=float)
        if self.fast:  # the per-pose path of a placement: no joint table walk
            q = self.template.copy()
            for k, lo, hi, j in self.slots:
                q[j.idx_q] = min(max(float(given[k]), lo), hi)
        else:
            named = {j.name: min(max(float(given[k]), lo), hi) for k, lo, hi, j in self.slots}
            q = self.ev.s.q(_values(self.ev.s, named))
        c0, p = self.ev.parts_at(q)
        out: NDArray[np.float64] = (self.ev.M * c0 + self.m * p) / (self.ev.M + self.m)
        return out

    def height(self, values: ArrayLike) -> float:
        """[m] the centre of mass above the ground with the joints at `values`."""
        return self.ev.s.height(self.com(values))


def _point_label(stance: Stance) -> str:
    p = stance.payload
    return "" if p is None else p.label.split(" at ", 1)[1]


def _values(stance: Stance, values: dict[str, float]) -> list[float]:
    """The searched joints' values of a pose, clamped into range; a joint it leaves out rests."""
    return [
        float(np.clip(values.get(j.name, j.rest), lo, hi))
        for j, (lo, hi) in zip(stance.joints, stance.box, strict=True)
    ]


def _at(
    ev: _Mass, name: str, x: Sequence[float], m: float, threshold: float, *, payload: bool = True
) -> PoseBalance:
    """The balance at joint values x with payload m (and the largest payload there)."""
    c0, p = ev.parts(x)
    c = (ev.M * c0 + m * p) / (ev.M + m)
    poly = ev.s.polygon
    d = poly.edge_distances(c)
    h = ev.s.height(c)
    return PoseBalance(
        name=name,
        q=tuple((jr.name, float(v)) for jr, v in zip(ev.s.joints, x, strict=True)),
        com=(float(c[0]), float(c[1]), float(c[2])),
        margins=tuple(float(v) for v in d),
        tip_angles=tuple(math.atan2(float(v), h) for v in d),
        margin=poly.margin(c),
        payload_max=_payload_max(ev, c0, p, threshold)
        if payload and ev.payload is not None
        else None,
    )


def _payload_max(ev: _Mass, c0: NDArray[Any], p: NDArray[Any], threshold: float) -> float | None:
    """The largest mass [kg] at point p keeping every edge margin >= threshold; None: not even 0.

    The centre of mass with m at p is (M c0 + m p) / (M + m), so each edge's margin is
    (M d(c0) + m d(p)) / (M + m): linear-fractional in m, with the bound in closed form.
    """
    poly = ev.s.polygon
    d0, dp = poly.edge_distances(c0), poly.edge_distances(p)
    if np.any(d0 < threshold - PAYLOAD_TOL):
        return None
    limits = [
        ev.M * (a - threshold) / (threshold - b)
        for a, b in zip(d0, dp, strict=True)
        if b < threshold
    ]
    return max(0.0, min(limits)) if limits else math.inf


def _seeds(stance: Stance, named: list[list[float]]) -> list[list[float]]:
    return sampling.search_starts(stance.box, BALANCE_DRAWS, named=named)


def _search(
    ev: _Mass,
    seeds: list[list[float]],
    m: float,
    threshold: float,
    *,
    tips: bool = True,
    previous: Sequence[PoseBalance] = (),
) -> tuple[tuple[PoseBalance, ...], tuple[float, ...]]:
    """Per edge: the configuration of least margin, and the least tipping angle.

    `previous`: a search's per-edge worst at another payload, each edge's warm start.
    """
    poly = ev.s.polygon
    coms = np.array([ev.com(x, m) for x in seeds])
    h = coms[:, 2] - ev.s.ground.height
    d_all = poly.offsets[None, :] - coms[:, :2] @ poly.normals.T  # (seeds, edges)
    worst: list[PoseBalance] = []
    angles: list[float] = []
    warm: list[list[float]] = []  # the previous edge's optima: a neighbour's are close
    for e, edge in enumerate(poly.edges):
        n = np.asarray(edge.normal)

        def margin(x: NDArray[Any], n: NDArray[Any] = n, off: float = edge.offset) -> Any:
            c, J = ev.com_jac(x, m)
            return off - n @ c[:2], -(n @ J[:2])

        def tip(x: NDArray[Any], n: NDArray[Any] = n, off: float = edge.offset) -> Any:
            c, J = ev.com_jac(x, m)
            d, hh = off - n @ c[:2], ev.s.height(c)
            grad = (hh * -(n @ J[:2]) - d * J[2]) / (d * d + hh * hh)
            return math.atan2(d, hh), grad

        before = [[v for _, v in previous[e].q]] if previous else warm[:1]
        x_m = _descend(margin, seeds, d_all[:, e], ev.s, warm=before)
        worst.append(_at(ev, WORST, x_m, m, threshold, payload=False))
        if tips:
            x_t = _descend(tip, seeds, np.arctan2(d_all[:, e], h), ev.s, warm=warm[1:])
            at_t = _at(ev, WORST, x_t, m, threshold, payload=False)
            angles.append(min(at_t.tip_angles[e], worst[-1].tip_angles[e]))
            warm = [x_m, x_t]
        else:
            warm = [x_m]
    return tuple(worst), tuple(angles)


def _descend(
    fun: Any,
    seeds: list[list[float]],
    values: NDArray[Any],
    stance: Stance,
    *,
    warm: Sequence[list[float]] = (),
) -> list[float]:
    """Projected gradient descent within the joint limits from the best seeds; the best point.

    `warm`: the neighbouring edge's optimum, descended first (a round base has dozens of
    edges whose worst configurations barely differ: from there the descent is short).
    """
    if not stance.joints:
        return []
    lower = [lo for lo, _ in stance.box]
    upper = [hi for _, hi in stance.box]
    best_x, best_f = seeds[int(np.argmin(values))], float(np.min(values))
    fresh = 1 if warm else SEEDS_DESCENDED  # a warm start stands for the other seeds
    starts = [*warm, *(seeds[k] for k in np.argsort(values)[:fresh])]
    for x0 in starts:
        res = minimize_box(fun, x0, lower, upper, max_iterations=DESCENT_ITERATIONS)
        if res.f < best_f:
            best_x, best_f = [float(v) for v in res.x], res.f
    return list(best_x)


def _payload_over_range(
    ev: _Mass, seeds: list[list[float]], m: float, threshold: float
) -> float | None:
    """The largest payload [kg] keeping the margin >= threshold over the whole joint range.

    Every closed-form bound at a real configuration is an upper bound of the answer; the
    search's worst configuration for the current guess gives the next one, until the
    guess repeats. None when the robot fails unloaded.
    """
    if ev.payload is None:
        return None
    guess, bounds = (m if m > 0 else 1.0), [math.inf]
    worst: tuple[PoseBalance, ...] = ()
    for _ in range(PAYLOAD_ROUNDS):
        worst, _ = _search(ev, seeds, guess, threshold, tips=False, previous=worst)
        low = min(worst, key=lambda p: p.margins[p.edge])
        c0, p = ev.parts([v for _, v in low.q])
        bound = _payload_max(ev, c0, p, threshold)
        if bound is None:
            return None
        if not math.isfinite(bound):  # no edge threatened here: try heavier
            guess *= 10.0
            if guess > MAX_PAYLOAD:
                break
            continue
        bounds.append(bound)
        if abs(bound - guess) <= 1e-6 * max(1.0, guess):
            break
        guess = bound
    return min(bounds)
