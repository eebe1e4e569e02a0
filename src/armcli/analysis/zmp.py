"""The zero-moment point of the whole robot while its arm moves and its base drives.

Model: rigid bodies on rigid, flat, level ground; the base is held still on its
wheels (braked, no slip) while the arm follows the simulated motion, and optionally
the whole robot accelerates or brakes along the base's x axis at a_b (a diff-drive
base cannot accelerate sideways; turning and the wheels' own spin-up are left out).
Whole-body inverse dynamics (Pinocchio RNEA on the free-flyer model, payload
included) gives the wrench (f, n) the ground must apply at the root's origin to hold
the base: the root's acceleration is a_b x, the arm's joints move at (q, v, a). The
zero-moment point is the point on the ground plane (height z0) about which that
wrench has no horizontal moment:

    n' = n - (0, 0, z0) x f,    p_x = -n'_y / f_z,    p_y = n'_x / f_z

It is the centre of pressure of the contact forces whenever they can hold the base,
so it must stay inside the support polygon; outside, the robot tips about the nearest
edge. The wrench is affine in a_b (the root's column of the mass matrix is
m (x, c x x) for a pure translation), so accelerating and braking cost one RNEA.

The joint accelerations are those of the simulator's own steps: a_k = (v_{k+1} - v_k)/dt,
exactly what semi-implicit Euler applied in step k.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.analysis.stance import Stance
from armcli.analysis.support import SupportPolygon
from armcli.robot.joints import Joint
from armcli.robot.model import Robot
from armcli.urdf.doc import Urdf

MAX_SAMPLES = 20_000  # states whose zero-moment point is computed, at most (pairs of steps)
Case = Literal["arm motion", "accelerating", "braking"]
CASES: tuple[Case, Case, Case] = ("arm motion", "accelerating", "braking")
# gazebo_ros_diff_drive limits the change of each wheel's rim speed by this [m/s²]
# (its code multiplies the joint velocity by the radius before comparing): the base's
# linear acceleration. gz-sim's DiffDrive names it max_linear_acceleration [m/s²].
DRIVE_ACCEL_TAGS = ("max_wheel_acceleration", "max_linear_acceleration", "max_acceleration")


@dataclass(frozen=True)
class ZmpSeries:
    """The zero-moment point over a run: per kept state, and the worst moment."""

    t: NDArray[np.float64]  # (K,) [s]
    step: NDArray[np.int64]  # (K,) simulator steps
    zmp: NDArray[np.float64]  # (K, 3, 2) [m] root x-y per case (CASES)
    margin: NDArray[np.float64]  # (K, 3) [m] signed margin per case (CASES)
    base_accel: float  # [m/s²] |a_b| of the accelerating and braking cases
    threshold: float  # [m] margin below which the report warns
    impacts: int = 0  # kept states left out: a joint hit its hard stop in that step
    shift: NDArray[np.float64] | None = None  # (K,) [m per m/s²] backward x shift per a_b
    # per state whose point leaves the polygon: the centre of mass [m] and the rotational
    # inertia about it [kg·m²] (root axes), for the tipping bound (sim.tipping.excursions)
    bodies: dict[int, tuple[NDArray[np.float64], NDArray[np.float64]]] = field(default_factory=dict)

    def worst(self) -> tuple[int, int]:
        """(state index, case index) of the least margin."""
        k, c = np.unravel_index(int(np.argmin(self.margin)), self.margin.shape)
        return int(k), int(c)

    @property
    def min_margin(self) -> float:
        """[m] least margin over the run and the cases."""
        return float(np.min(self.margin))


def drive_acceleration(urdf: Urdf) -> float | None:
    """The diff-drive plugin's acceleration limit [m/s²] in the URDF's <gazebo>, if any."""
    for plugin in urdf.plugins:  # read once with the document (urdf.extensions)
        for tag in DRIVE_ACCEL_TAGS:
            text = plugin.params.get(tag)
            if text is not None:
                try:
                    value = float(text)
                except ValueError:
                    continue
                if math.isfinite(value) and value > 0:
                    return value
    return None


def zmp_steps(steps: int, also: ArrayLike = ()) -> NDArray[np.int64]:
    """The steps a run must keep for the zero-moment point: pairs (k, k + 1).

    Every step when there are at most MAX_SAMPLES, else evenly spread ones; plus the
    steps in `also` (the states file's), each with its successor.
    """
    k = np.round(np.linspace(0, steps - 1, min(steps, MAX_SAMPLES))).astype(np.int64)
    k = np.concatenate([k, np.asarray(also, dtype=np.int64)])
    k = k[(k >= 0) & (k <= steps)]
    return np.sort(np.concatenate([k, np.minimum(k + 1, steps)]))


def accelerations(
    step: NDArray[Any], v: NDArray[Any], dt: float, impact: NDArray[Any] | None = None
) -> tuple[NDArray[Any], NDArray[Any]]:
    """(rows, a): the kept states with a known acceleration and that acceleration.

    Forward difference where the next step was kept, else backward where the previous
    was (the run's last state); states with neither are left out, and so are the steps
    marked in `impact` (a joint running into its hard stop: an impulse, not a force).
    """
    nxt = np.concatenate([np.diff(step) == 1, [False]])
    prv = np.concatenate([[False], np.diff(step) == 1])
    usable = nxt | prv
    if impact is not None:
        hit = np.asarray(impact, dtype=bool)
        usable &= ~np.where(nxt, hit, np.concatenate([[False], hit[:-1]]))
    rows = np.nonzero(usable)[0]
    fwd = nxt[rows]
    later = np.where(fwd, rows + 1, rows)  # forward where the next step was kept, else back
    earlier = np.where(fwd, rows, rows - 1)
    return rows, (v[later] - v[earlier]) / dt


def impacts(stop: NDArray[Any], v: NDArray[Any]) -> NDArray[np.bool_]:
    """Per kept state: a joint stop acted in its step while that joint was moving."""
    return np.asarray(np.any(np.asarray(stop, dtype=bool) & (np.asarray(v) != 0.0), axis=1))


def zmp_series(
    stance: Stance,
    joint_names: Sequence[str],
    t: NDArray[Any],
    step: NDArray[Any],
    q: NDArray[Any],
    v: NDArray[Any],
    dt: float,
    base_accel: float,
    threshold: float,
    impact: NDArray[Any] | None = None,
) -> ZmpSeries:
    """The zero-moment point at every kept state of a run whose acceleration is known.

    `q`, `v` are the simulated joints' positions and velocities at the kept `step`s,
    `joint_names` their names in the whole robot (a joint missing there is an error);
    states flagged in `impact` (joint-stop impacts, `impacts`) are left out.
    """
    import pinocchio as pin

    loaded = stance.loaded()
    model, data = loaded.model, loaded.data
    rows, a = accelerations(np.asarray(step), np.asarray(v), dt, impact)
    skipped = 0 if impact is None else int(np.sum(np.asarray(impact, dtype=bool)))
    cols = _columns(stance.robot, joint_names)
    to_q = stance.robot.joint_map(joint_names)  # others at rest, as simulate locks them
    iv = [j.idx_v for j in cols]
    mass = loaded.mass
    z0 = stance.ground.height
    w, c = np.empty((len(rows), 6)), np.empty((len(rows), 3))
    vk, ak = np.zeros(model.nv), np.zeros(model.nv)
    for i, r in enumerate(rows):  # Pinocchio per state; the rest at once below
        qk = to_q.q(np.asarray(q[r], dtype=float))
        vk[iv], ak[iv] = v[r], a[i]
        w[i] = pin.rnea(model, data, qk, vk, ak)[:6]
        c[i] = pin.centerOfMass(model, data, qk, False)
    dw = mass * np.column_stack([np.ones(len(rows)), np.zeros((len(rows), 3)), c[:, 2], -c[:, 1]])
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(w[:, 2] > 0, mass * (c[:, 2] - z0) / w[:, 2], math.inf)
    cases = np.stack([w + sign * base_accel * dw for sign in (0.0, 1.0, -1.0)], axis=1)
    zmp = zero_moment_points(cases, z0)  # (K, 3, 2)
    margin = stance.polygon.margins(zmp.reshape(-1, 2)).reshape(len(rows), 3)
    bodies: dict[int, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}
    outside = np.nonzero(np.min(margin, axis=1) < 0)[0] if len(rows) else np.zeros(0, int)
    for i in (int(k) for k in outside):  # the tipping bound's inputs (sim.tipping)
        qk = to_q.q(np.asarray(q[rows[i]], dtype=float))
        pin.ccrba(model, data, qk, np.zeros(model.nv))
        bodies[i] = (c[i].copy(), np.array(data.Ig.inertia, dtype=float))
    return ZmpSeries(
        np.asarray(t)[rows],
        np.asarray(step)[rows],
        zmp,
        margin,
        float(base_accel),
        float(threshold),
        skipped,
        shift,
        bodies,
    )


def max_base_accel(series: ZmpSeries, polygon: SupportPolygon, threshold: float) -> float:
    """The largest |a_b| [m/s²] for which the point keeps `threshold` margin at every state.

    The base's acceleration moves the point along x only, by -a_b m h / f_z (`shift`):
    f_z does not change and the moment about the y axis grows by m h a_b. So each edge
    bounds a_b in closed form; 0 when the arm motion alone leaves too little margin.
    """
    assert series.shift is not None
    if len(series.shift) == 0:
        return math.inf
    p = np.asarray(series.zmp[:, 0], dtype=float)  # (n, 2), all states at once
    d = polygon.offsets[None, :] - p @ polygon.normals.T - threshold  # (n, k) slack per edge
    if np.any(d < 0):  # NaN (lifted off) compares false, as it did state by state
        return 0.0
    s = np.asarray(series.shift, dtype=float)[:, None]
    n_x = np.abs(polygon.normals[:, 0])[None, :]
    use = (n_x > 1e-12) & (s > 0) & ~np.isnan(d)  # both signs of a_b: either side's edges
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = np.where(use, d / (s * n_x), math.inf)
    return float(np.min(bound))


def zero_moment_point(wrench: NDArray[Any], ground: float = 0.0) -> NDArray[np.float64]:
    """The point [m] on the ground plane z = `ground` where the wrench has no horizontal moment.

    `wrench` = (f, n): force [N] and moment [N·m] about the root's origin, root frame.
    NaN when f_z <= 0: nothing presses the robot on the ground (it lifts off).
    """
    f, n = wrench[:3], wrench[3:6]
    if f[2] <= 0.0:
        return np.array([math.nan, math.nan])
    nx = n[0] + ground * f[1]
    ny = n[1] - ground * f[0]
    return np.array([-ny / f[2], nx / f[2]])


def zero_moment_points(wrenches: NDArray[Any], ground: float = 0.0) -> NDArray[np.float64]:
    """`zero_moment_point` of every wrench in (..., 6) at once: (..., 2), NaN where f_z <= 0."""
    f, n = wrenches[..., :3], wrenches[..., 3:6]
    nx = n[..., 0] + ground * f[..., 1]
    ny = n[..., 1] - ground * f[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.stack([-ny / f[..., 2], nx / f[..., 2]], axis=-1)
    p[f[..., 2] <= 0.0] = math.nan
    return np.asarray(p, dtype=float)


def _columns(robot: Robot, names: Sequence[str]) -> list[Joint]:
    """Each simulated joint in the whole robot."""
    known = set(robot.names)
    missing = [n for n in names if n not in known]
    if missing:
        raise ValueError(f"joint {missing[0]!r} is not in the whole robot")
    return [robot.joint(n) for n in names]
