"""The PD(+I) loop of a controller that holds its torque between updates (zero-order hold).

A ros2_control controller in Gazebo does not run at the physics step: gz_ros2_control
reads the joints and updates the controllers every 1/update_rate of simulated time
(`PostUpdate`) and writes the last command at every physics step in between (`PreUpdate`:
"always set commands on joints, otherwise at low control frequencies the joints tremble").
So the JointTrajectoryController's effort is a zero-order hold of hold time T =
1/update_rate on an arm that the physics integrates finely: a sampled-data loop, not the
Euler step `analysis.stability` bounds at the simulator's dt.

Linearised at an operating point, the controlled joints obey M_c x'' = u - G_c x - D_p x'
(M_c = ((M^-1)_cc)^-1: the joints without gains are free and carry no stiffness, wheels
and casters, the smallest inertia the controlled joints can see; G_c gravity's stiffness
on them; D_p their viscous damping, which the physics applies continuously). Over one hold
the exact step is (x, v)+ = Phi (x, v) + Gamma u with [[Phi, Gamma], [0, I]] =
expm([[F, B], [0, 0]] T). control_toolbox's PID on the sampled error e = -x, e' = -v:

    i_k = i_(k-1) + Ki T e_k,   u_k = Kp e_k + Kd e'_k + i_k

gives the closed-loop map of (x, v, i_(k-1)); the loop is stable when its spectral radius
is <= 1. For one joint without integral (a = Kp T² / m, b = (Kd + D_p) T / m, D_p ~ 0) this
is Jury's a / 2 < b < 2: the hold delays the torque by T / 2 on average, which takes
Kp T / 2 off the damping, and too much Kd overshoots within one hold (b >= 2).

Where Kp + G_c is not positive semidefinite gravity beats the gains (the continuous loop
itself cannot hold the arm there, at any rate): such points say nothing about the rate
and are left out (`ros-start-sag` and `gravity-effort` speak about them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.analysis.pdloop import PD, Array, Linearised

RADIUS_TOL = 1e-9  # as analysis.stability: |z| <= 1 + RADIUS_TOL is stable
PSD_RTOL = 1e-12  # Kp + G_c counts as positive semidefinite down to this relative slack
BISECT_STEPS = 50  # halvings of the largest stable hold (relative error 2^-50)
HOLD_CEILING = 100.0  # [s] a loop stable at this hold is stable at every rate
SCALE_FLOOR = 1e-6  # the smallest gain factor tried
EXPM_NORM = 0.5  # expm: scaled to this norm, where TAYLOR_TERMS terms suffice
TAYLOR_TERMS = 14  # 0.5^15 / 15! ~ 2e-17


@dataclass(frozen=True)
class Held:
    """The controlled joints at every operating point: what the hold acts on."""

    Mc_inv: Array  # (S, n, n) (M^-1)_cc [1/(kg·m²)]
    Gc: Array  # (S, n, n) gravity's stiffness on the controlled joints [N·m/rad]
    index: NDArray[np.bool_]  # (S0,) which of the original points these are

    def take(self, mask: NDArray[np.bool_]) -> Held:
        """The points where `mask` is true."""
        index = self.index.copy()
        index[np.flatnonzero(index)[~mask]] = False
        return Held(self.Mc_inv[mask], self.Gc[mask], index)

    def holds(self, pid: Pid) -> NDArray[np.bool_]:
        """(S,) where Kp + G_c >= 0: the gains can hold the arm there (else left out)."""
        K = self.Gc + np.diag(pid.pd.kp)
        scale = max(1.0, float(np.abs(pid.pd.kp).max(initial=0.0)))
        low = np.linalg.eigvalsh(0.5 * (K + np.swapaxes(K, 1, 2)))[:, 0]
        out: NDArray[np.bool_] = low >= -PSD_RTOL * scale
        return out


@dataclass(frozen=True)
class Pid:
    """The controller's gains on the controlled joints (one entry each) and their damping."""

    pd: PD
    ki: Array  # [N·m/(rad·s)]; zeros without an integral term

    @staticmethod
    def of(pd: PD, ki: ArrayLike | None = None) -> Pid:
        """PD gains with an integral term (zeros when None)."""
        return Pid(pd, np.zeros_like(pd.kp) if ki is None else np.asarray(ki, dtype=float))

    def scaled(self, s: float) -> Pid:
        """Kp and Kd x s, Ki x s²: slower by s, the integral keeping its share of the loop.

        (The PID's Routh bound Ki M < (Kd + D) Kp scales as s² on both sides.)
        """
        return Pid(self.pd.scaled(s, s), self.ki * s * s)


def reduce(lin: Linearised, pid: Pid) -> Held:
    """The controlled joints' inverse inertia and stiffness at every point (`pid`: which)."""
    idx = list(pid.pd.idx)
    Minv = np.asarray(np.linalg.inv(lin.M), dtype=float)[:, idx][:, :, idx]
    Mc_inv: Array = 0.5 * (Minv + np.swapaxes(Minv, 1, 2))
    Gc = lin.G[:, idx][:, :, idx]
    return Held(Mc_inv, Gc, np.ones(len(lin), dtype=bool))


def closed_loop(h: Held, pid: Pid, hold: float) -> Array:
    """(S, m, m) the closed-loop map over one hold of (x, v[, i]) at every point.

    Integral states only for the joints with Ki > 0 (the others' would sit at 1 for ever).
    """
    S, n = h.Mc_inv.shape[0], h.Mc_inv.shape[1]
    Dp = np.diag(pid.pd.damping)
    aug = np.zeros((S, 3 * n, 3 * n))
    aug[:, :n, n : 2 * n] = np.eye(n)
    aug[:, n : 2 * n, :n] = -h.Mc_inv @ h.Gc
    aug[:, n : 2 * n, n : 2 * n] = -h.Mc_inv @ Dp
    aug[:, n : 2 * n, 2 * n :] = h.Mc_inv
    E = expm(aug * hold)
    Phi, Gam = E[:, : 2 * n, : 2 * n], E[:, : 2 * n, 2 * n :]
    kp, kd, ki = pid.pd.kp, pid.pd.kd, pid.ki
    gain = np.hstack([np.diag(kp + ki * hold), np.diag(kd)])  # u = -gain (x, v) + i
    A = Phi - Gam @ gain
    integ = np.flatnonzero(ki > 0.0)
    if integ.size == 0:
        out: Array = A
        return out
    m = 2 * n + integ.size
    full = np.zeros((S, m, m))
    full[:, : 2 * n, : 2 * n] = A
    full[:, : 2 * n, 2 * n :] = Gam[:, :, integ]
    full[:, 2 * n :, integ] = -np.diag(ki[integ] * hold)
    full[:, 2 * n :, 2 * n :] = np.eye(integ.size)
    return full


def expm(A: Array) -> Array:
    """exp(A) of each matrix of an (S, m, m) batch: Taylor series, scaling and squaring.

    numpy-batched (scipy's expm loops in Python over a batch: ~1 ms per small matrix); the
    matrices are scaled to a norm <= EXPM_NORM, where TAYLOR_TERMS terms leave a relative
    remainder below 1e-16, then squared back. tests/analysis/test_zoh.py holds it to scipy.
    """
    norm = float(np.max(np.abs(A).sum(axis=2), initial=0.0))  # the largest infinity norm
    squarings = max(0, math.ceil(math.log2(norm / EXPM_NORM))) if norm > 0 else 0
    X = A / 2.0**squarings
    eye = np.broadcast_to(np.eye(A.shape[-1]), A.shape)
    E, term = eye.copy(), eye.copy()
    for k in range(1, TAYLOR_TERMS + 1):
        term = term @ X / k
        E = E + term
    for _ in range(squarings):
        E = E @ E
    return E


def radii(h: Held, pid: Pid, hold: float) -> Array:
    """(S,) the spectral radius of the closed loop at each point (0 where left out)."""
    held = h.holds(pid)
    out = np.zeros(len(held))
    if np.any(held):
        loop = closed_loop(h.take(held), pid, hold)
        out[held] = np.max(np.abs(np.linalg.eigvals(loop)), axis=1)
    return out


def stable(h: Held, pid: Pid, hold: float) -> bool:
    """Whether the held loop is stable at every point the gains can hold."""
    return bool(np.all(radii(h, pid, hold) <= 1.0 + RADIUS_TOL))


def hold_max(h: Held, pid: Pid, start: float) -> tuple[float, int]:
    """The largest stable hold [s] (inf: every hold up to HOLD_CEILING) and the point setting it.

    The stable holds are taken to be an interval from 0 (the one-joint condition is two
    upper bounds on T), bracketed from `start`; only the points that fail at the bracket's
    top are bisected (a point stable there is stable below it).
    """
    lo, hi = start, start
    while stable(h, pid, hi):
        lo, hi = hi, 2.0 * hi
        if hi > HOLD_CEILING:
            return math.inf, int(np.argmax(radii(h, pid, start)))
    if lo == hi:
        lo = 0.0
    bad = h.take(radii(h, pid, hi) > 1.0 + RADIUS_TOL)
    for _ in range(BISECT_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(bad, pid, mid) else (lo, mid)
    worst = np.flatnonzero(bad.index)[int(np.argmax(radii(bad, pid, hi)))]
    return lo, int(worst)


def holds_stably(h: Held, pid: Pid, hold: float) -> bool:
    """Whether `pid` holds the arm at every point of `h` (Kp + G_c >= 0) and stably there.

    What lower gains must do at the points the configured gains hold: gains that gravity
    beats are no remedy, though `stable` would leave those points out.
    """
    return bool(np.all(h.holds(pid))) and stable(h, pid, hold)


def gain_scale(h: Held, pid: Pid, hold: float) -> float | None:
    """The largest factor s <= 1 (Pid.scaled) stable at `hold`; None when none >= SCALE_FLOOR is.

    1.0 when the gains are stable. Lower gains must still hold the arm where these do
    (`holds_stably` on those points). They are not always stable here (a hold needs some
    damping: Kd > Kp T / 2), so the search starts from the smallest factor that is.
    """
    if stable(h, pid, hold):
        return 1.0
    h = h.take(h.holds(pid))
    s = 0.5
    while not holds_stably(h, pid.scaled(s), hold):
        s *= 0.5
        if s < SCALE_FLOOR:
            return None
    lo, hi = s, min(1.0, 2.0 * s)
    for _ in range(BISECT_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if holds_stably(h, pid.scaled(mid), hold) else (lo, mid)
    return lo
