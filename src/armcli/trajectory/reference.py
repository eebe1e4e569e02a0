"""Piecewise-polynomial reference built from a Trajectory: what the simulator tracks.

Segments are stored as quintic coefficients in local time (linear and cubic segments have
zero higher terms). The compiled engine receives these arrays (sim/rollout.py hands them
over) and evaluates them itself at every step; `Reference.sample` evaluates the same
polynomials in NumPy for everything outside the step: speed prechecks, the planner's
certificate, driving's arm commands, plots and the tests' independent integrators.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from armcli.robot.mimic import Mimic
from armcli.trajectory.message import Trajectory


@dataclass(frozen=True)
class Reference:
    """q_ref(t), v_ref(t) for every model joint; held constant after the last knot."""

    knots: np.ndarray  # (S + 1,) segment boundaries [s]
    coeffs: np.ndarray  # (S, 6, n) c0..c5 of q(tau) = sum c_k tau^k, tau = t - knots[s]
    final: np.ndarray  # (n,) position held after the last knot

    def sample(
        self, t: np.ndarray, segment_time: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Reference positions and velocities at times `t`, each (len(t), n).

        `segment_time` (same length) picks the polynomial piece evaluated at each `t`
        (default: the piece holding `t`). The compiled RK4 step evaluates the piece of its
        midpoint so that all its stages see one smooth function (rollout.cpp); a reference
        integrator reproduces that through `segment_time`.
        """
        t = np.asarray(t, dtype=float)
        ts = t if segment_time is None else np.asarray(segment_time, dtype=float)
        n = self.final.shape[0]
        q = np.broadcast_to(self.final, (t.shape[0], n)).copy()
        v = np.zeros((t.shape[0], n))
        if self.coeffs.shape[0] == 0:
            return q, v
        inside = ts < self.knots[-1]
        idx = np.clip(np.searchsorted(self.knots, ts[inside], side="right") - 1, 0, None)
        tau = (t[inside] - self.knots[idx])[:, None]
        c = self.coeffs[idx]  # (T, 6, n)
        qi = c[:, 5]
        vi = 5.0 * c[:, 5]
        for k in (4, 3, 2, 1, 0):
            qi = qi * tau + c[:, k]
            if k >= 1:
                vi = vi * tau + k * c[:, k]
        q[inside], v[inside] = qi, vi
        return q, v


def coupled(ref: Reference, pairs: Sequence[tuple[int, int, Mimic]]) -> Reference:
    """`ref` with each follower column set to multiplier * leader + offset (leaders first)."""
    if not pairs:
        return ref
    coeffs, final = ref.coeffs.copy(), ref.final.copy()
    for f, lead, m in pairs:
        coeffs[:, :, f] = m.multiplier * coeffs[:, :, lead]
        coeffs[:, 0, f] += m.offset
        final[f] = m.position(final[lead])
    return Reference(knots=ref.knots, coeffs=coeffs, final=final)


def segment_coeffs(
    h: float,
    p0: np.ndarray,
    p1: np.ndarray,
    v0: np.ndarray | None = None,
    v1: np.ndarray | None = None,
    a0: np.ndarray | None = None,
    a1: np.ndarray | None = None,
) -> np.ndarray:
    """(6, n) coefficients over [0, h]: linear, cubic (v0, v1) or quintic (also a0, a1).

    The same closed forms as joint_trajectory_controller's interpolation.
    """
    n = p0.shape[0]
    c = np.zeros((6, n))
    dp = p1 - p0
    c[0] = p0
    if v0 is None or v1 is None:
        c[1] = dp / h
        return c
    c[1] = v0
    if a0 is None or a1 is None:
        c[2] = (3.0 * dp - (2.0 * v0 + v1) * h) / h**2
        c[3] = (-2.0 * dp + (v0 + v1) * h) / h**3
        return c
    c[2] = 0.5 * a0
    c[3] = (20.0 * dp - (8.0 * v1 + 12.0 * v0) * h - (3.0 * a0 - a1) * h**2) / (2.0 * h**3)
    c[4] = (-30.0 * dp + (14.0 * v1 + 16.0 * v0) * h + (3.0 * a0 - 2.0 * a1) * h**2) / (2.0 * h**4)
    c[5] = (12.0 * dp - 6.0 * (v1 + v0) * h - (a0 - a1) * h**2) / (2.0 * h**5)
    return c


def build_reference(traj: Trajectory, joint_names: Sequence[str], q_start: np.ndarray) -> Reference:
    """Reference for the model joints `joint_names`, starting at rest at `q_start`.

    Joints the trajectory does not name hold their start position.
    """
    n = len(joint_names)
    cols = [list(joint_names).index(name) for name in traj.joint_names]
    P = traj.positions.shape[0]

    def full(rows: np.ndarray | None, base: np.ndarray) -> np.ndarray | None:
        if rows is None:
            return None
        out = np.tile(base, (P, 1))
        out[:, cols] = rows
        return out

    zeros = np.zeros(n)
    pos = full(traj.positions, q_start)
    vel = full(traj.velocities, zeros)
    acc = full(traj.accelerations, zeros)
    assert pos is not None
    knots = [float(t) for t in traj.times]
    segs = []
    if knots[0] > 0.0:
        knots.insert(0, 0.0)
        first_v = zeros if vel is not None else None
        first_a = zeros if acc is not None else None
        segs.append(_coeffs(knots[1], q_start, pos, vel, acc, 0, first_v, first_a))
    rest = _segments(np.diff(traj.times), pos, vel, acc)
    coeffs = np.concatenate([np.array(segs).reshape(-1, 6, n), rest])
    # With a single point at t = 0 the reference is that point from the start.
    return Reference(knots=np.array(knots), coeffs=coeffs, final=pos[-1].copy())


def _segments(
    h: np.ndarray, pos: np.ndarray, vel: np.ndarray | None, acc: np.ndarray | None
) -> np.ndarray:
    """`segment_coeffs` of every segment between points at once, (S, 6, n): the same numbers.

    The same operations in the same order, element by element; the powers of h are taken
    one by one as `segment_coeffs` takes them (a numpy scalar's power is not always the
    array power's last bit).
    """
    S, n = len(h), pos.shape[1]
    c = np.zeros((S, 6, n))
    if S == 0:
        return c
    p0, dp = pos[:-1], pos[1:] - pos[:-1]
    hc = h[:, None]
    c[:, 0] = p0
    if vel is None:
        c[:, 1] = dp / hc
        return c
    v0, v1 = vel[:-1], vel[1:]
    c[:, 1] = v0
    h2, h3 = (np.array([x**k for x in h])[:, None] for k in (2, 3))
    if acc is None:
        c[:, 2] = (3.0 * dp - (2.0 * v0 + v1) * hc) / h2
        c[:, 3] = (-2.0 * dp + (v0 + v1) * hc) / h3
        return c
    a0, a1 = acc[:-1], acc[1:]
    h4, h5 = (np.array([x**k for x in h])[:, None] for k in (4, 5))
    c[:, 2] = 0.5 * a0
    c[:, 3] = (20.0 * dp - (8.0 * v1 + 12.0 * v0) * hc - (3.0 * a0 - a1) * h2) / (2.0 * h3)
    c[:, 4] = (-30.0 * dp + (14.0 * v1 + 16.0 * v0) * hc + (3.0 * a0 - 2.0 * a1) * h2) / (2.0 * h4)
    c[:, 5] = (12.0 * dp - 6.0 * (v1 + v0) * hc - (a0 - a1) * h2) / (2.0 * h5)
    return c


def _coeffs(
    h: float,
    p0: np.ndarray,
    pos: np.ndarray,
    vel: np.ndarray | None,
    acc: np.ndarray | None,
    k: int,
    v0: np.ndarray | None,
    a0: np.ndarray | None,
) -> np.ndarray:
    v1 = vel[k] if vel is not None else None
    a1 = acc[k] if acc is not None else None
    return segment_coeffs(h, p0, pos[k], v0, v1, a0, a1)
