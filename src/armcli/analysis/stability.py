"""Sampled-data stability of joint PD control: the one bound `check`, `simulate` and `tune` use.

Linearised at an operating point q*, the arm obeys M dq'' = -K dq - D dq' with

    K = Kp + G,  G = dg/dq (gravity's stiffness: the Hessian of the potential at q*;
                  zero with gravity compensation, which cancels g(q) at the same q),
    D = Kd + damping on the controlled joints (free joints: neither).

One semi-implicit Euler step, v+ = v + dt M_e^-1 (-K q - D v), q+ = q + dt v+, with
M_e = M (damping explicit, as a torque controller updated at every physics step dt, e.g.
ros2_control at 1/dt in Gazebo; a slower controller holds its torque: analysis.zoh) or
M_e = M + dt D (damping implicit, as armcli's simulator steps it). Its characteristic
polynomial z² M_e - z (2 M_e - dt D - dt² K) + (M_e - dt D), under the bilinear map
z = (1 + s) / (1 - s) (|z| <= 1 iff Re s <= 0), becomes

    s² A + s (2 dt D) + dt² K,   A = 4 M + 2 c dt D - dt² K,   c = +1 implicit, -1 explicit.

All three matrices are symmetric. With K, D >= 0 every eigenpair gives a s² + b s + c = 0
with a = x*Ax, b, c >= 0, so A >= 0 (positive semidefinite) keeps |z| <= 1; and if A has a
negative direction, det(A + tau B + tau² C) changes sign on tau > 0, which is a real
|z| > 1. So **the step is stable iff A >= 0**: one Cholesky factorisation per sample
instead of a 2n x 2n eigenvalue problem, which keeps the analysis cheap on 128-DoF models.
For one joint (lambda = 1/m) it is the Jury condition a + 2 c b <= 4 with a = Kp dt² lambda,
b = D dt lambda. Where gravity tips the arm (K not >= 0) the continuous loop itself is
statically unstable at that point; A >= 0 then still says the step adds no growth of its
own, which is what a smaller dt can fix.

A is decreasing in dt (A / dt² = 4 M / dt² + 2 c D / dt - K), so the stable time steps
are an interval [0, dt_max], found by bisection; A is affine in a common gain scale s, so
the largest stable scale is a generalised eigenvalue (closed form). `suggest` turns both
into the remedy that `check` reports and `simulate` prints (armcli.analysis.verdict).

RK4 has no implicit damping: its step map is the 4th-order Taylor polynomial p(h mu) of
the continuous modes mu (eigenvalues of the linearised loop), stable where |p| <= 1.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np
from numpy.typing import NDArray

from armcli.analysis.pdloop import PD, Array, Linearised, Scaled, Scheme

# The loop counts as stable when its step map does not grow: spectral radius <= 1 + RADIUS_TOL
# (RK4 and reports), or A + PSD_RTOL * 4M positive definite (Euler). Undamped symplectic
# Euler sits exactly on |z| = 1 (a bounded oscillation); the slack absorbs rounding there.
RADIUS_TOL = 1e-9
PSD_RTOL = 1e-10
BISECT_STEPS = 60  # halvings for the largest stable dt (relative error 2^-60)
DT_CEILING = 1e6  # [s] a loop stable beyond this is stable for every dt


# -- scalar modes (the closed forms the matrix bound reduces to for one joint) ----------------


def explicit_stable(a: float, b: float) -> bool:
    """Jury test for the explicit-damping mode: a > 0 and a + 2b < 4."""
    return a > 0.0 and a + 2.0 * b < 4.0


def explicit_dt_max(kp: float, d: float, lam: float) -> float:
    """Largest dt with Kp lam dt² + 2 D lam dt < 4 [s]."""
    if kp <= 0.0:
        return 2.0 / (d * lam) if d > 0 else math.inf
    return (-d * lam + math.sqrt((d * lam) ** 2 + 4.0 * kp * lam)) / (kp * lam)


def implicit_dt_max(kp: float, d: float, lam: float) -> float:
    """Largest dt with Kp lam dt² - 2 D lam dt < 4 [s]."""
    if kp <= 0.0:
        return math.inf
    return (d * lam + math.sqrt((d * lam) ** 2 + 4.0 * kp * lam)) / (kp * lam)


# -- Euler: A >= 0 --------------------------------------------------------------------------


def _diag(n: int, pd: PD, values: Array) -> Array:
    out = np.zeros(n)
    out[list(pd.idx)] = values
    return out


def margin_matrix(M: Array, G: Array, pd: PD, dt: float, scheme: Scheme) -> Array:
    """A = 4 M + 2 c dt D - dt² (Kp + G): the Euler step is stable iff A >= 0."""
    n = M.shape[0]
    c = 1.0 if scheme == "implicit" else -1.0
    d = _diag(n, pd, pd.kd + pd.damping)
    k = _diag(n, pd, pd.kp)
    A = 4.0 * M - dt * dt * G
    A[np.diag_indices(n)] += 2.0 * c * dt * d - dt * dt * k
    return A


def _psd(A: Array, M: Array) -> bool:
    """A >= 0 up to PSD_RTOL relative to 4M (Cholesky of the slightly lifted matrix)."""
    try:
        np.linalg.cholesky(A + (4.0 * PSD_RTOL) * M)
    except np.linalg.LinAlgError:
        return False
    return True


def _euler_ok(lin: Linearised, k: int, pd: PD, dt: float, *, scheme: Scheme) -> bool:
    return _psd(margin_matrix(lin.M[k], lin.G[k], pd, dt, scheme), lin.M[k])


def _edge(ok: Callable[[float], bool], start: float) -> float:
    """Largest x > 0 with ok(x), for ok true below one edge: bracket from `start`, bisect."""
    lo, hi = 0.0, start
    if ok(start):
        lo, hi = start, 2.0 * start
        while ok(hi):
            lo, hi = hi, 2.0 * hi
            if hi > DT_CEILING:
                return math.inf
    else:
        while not ok(hi / 2.0):
            hi /= 2.0
            if hi < 1e-300:
                return 0.0
        lo = hi / 2.0
    for _ in range(BISECT_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


def _euler_dt_max(lin: Linearised, pd: PD, scheme: Scheme, start: float) -> tuple[float, int]:
    """Largest stable dt over all points and the point that sets it.

    A point stable at the best dt so far cannot lower it (A decreases with dt), so each
    point costs one factorisation and only the few that lower the bound are bisected.
    """
    best, worst = math.inf, 0
    for k in range(len(lin)):
        if math.isfinite(best) and _euler_ok(lin, k, pd, best, scheme=scheme):
            continue
        edge = _edge(partial(_euler_ok, lin, k, pd, scheme=scheme), min(start, best))
        if edge < best:
            best, worst = edge, k
    return best, worst


def largest_along(lin: Linearised, base: PD, p: Array, dt: float, scheme: Scheme) -> float | None:
    """Largest s >= 0 with A(base) - s diag(p) >= 0 at every point (inf: any s; None: not 0).

    A is affine in s, so per point s* = 1 / lambda_max(P^1/2 A(base)^-1 P^1/2), a symmetric
    eigenvalue problem on the controlled joints; a point already >= 0 at the best s so far
    cannot lower it and costs one factorisation.
    """
    idx = list(base.idx)
    n = lin.M.shape[1]
    full = _diag(n, base, p)
    best = math.inf
    for k in range(len(lin)):
        M = lin.M[k]
        A0 = margin_matrix(M, lin.G[k], base, dt, scheme)
        if math.isfinite(best) and _psd(A0 - best * np.diag(full), M):
            continue
        if not _psd(A0, M):
            return None
        if not idx:
            continue
        sq = np.sqrt(p)
        W = np.linalg.inv(A0 + (4.0 * PSD_RTOL) * M)[np.ix_(idx, idx)] * np.outer(sq, sq)
        top = float(np.linalg.eigvalsh(0.5 * (W + W.T))[-1])
        best = min(best, 1.0 / top if top > 0.0 else math.inf)
    return best


@dataclass(frozen=True)
class GainScale:
    """The largest stable factor on some of the gains at dt: which gains, and how far."""

    factor: float  # >= 1 when the gains are stable; inf: any factor
    kp: bool  # Kp is scaled
    kd: bool  # Kd is scaled

    @property
    def label(self) -> Scaled:
        """The scaled gains, in words."""
        return "Kp and Kd" if self.kp and self.kd else ("Kp" if self.kp else "Kd")

    def apply(self, pd: PD, s: float) -> PD:
        """`pd` with the scaled gains multiplied by s."""
        return pd.scaled(s if self.kp else 1.0, s if self.kd else 1.0)


def _euler_scale(lin: Linearised, pd: PD, dt: float, scheme: Scheme) -> GainScale | None:
    """Largest stable factor at dt on every point, along the gains that matter.

    Implicit damping: Kp alone (Kd makes that loop more stable, never less). Explicit
    damping: Kd alone when vanishing Kd would be stable (Kp kept), else Kp and Kd together.
    """
    if scheme == "implicit":
        directions = [GainScale(0.0, kp=True, kd=False)]
    else:
        directions = [GainScale(0.0, kp=True, kd=True)]
        if np.any(pd.kd > 0.0):
            directions.insert(0, GainScale(0.0, kp=False, kd=True))
    for d in directions:
        p = (dt * dt * pd.kp if d.kp else 0.0 * pd.kp) + (2.0 * dt * pd.kd if d.kd else 0.0)
        factor = largest_along(lin, d.apply(pd, 0.0), p, dt, scheme)
        if factor is not None:
            return GainScale(factor, d.kp, d.kd)
    return None


# -- RK4: continuous modes through the Taylor polynomial ------------------------------------


def continuous_modes(M: Array, G: Array, pd: PD) -> NDArray[np.complex128]:
    """Eigenvalues mu of the linearised continuous loop M x'' + D x' + (Kp + G) x = 0."""
    n = M.shape[0]
    K = G + np.diag(_diag(n, pd, pd.kp))
    D = np.diag(_diag(n, pd, pd.kd + pd.damping))
    Minv = np.linalg.inv(M)
    top = np.hstack([np.zeros((n, n)), np.eye(n)])
    mu = np.linalg.eigvals(np.vstack([top, np.hstack([-Minv @ K, -Minv @ D])]))
    return np.asarray(mu, dtype=np.complex128)


def _rk4_radius(mu: NDArray[np.complex128], h: float) -> float:
    """Largest |p(h mu)| over the modes the continuous loop itself keeps bounded."""
    z = h * mu[mu.real <= RADIUS_TOL * np.maximum(1.0, np.abs(mu))]
    if z.size == 0:
        return 1.0
    p = 1.0 + z * (1.0 + z / 2.0 * (1.0 + z / 3.0 * (1.0 + z / 4.0)))
    return float(np.max(np.abs(p)))


def _rk4_ok(mu: NDArray[np.complex128], h: float) -> bool:
    return _rk4_radius(mu, h) <= 1.0 + RADIUS_TOL


def _rk4_dt_max(modes: Sequence[NDArray[np.complex128]], start: float) -> tuple[float, int]:
    best, worst = math.inf, 0
    for k, mu in enumerate(modes):
        edge = _edge(partial(_rk4_ok, mu), min(start, best))
        if edge < best:
            best, worst = edge, k
    return best, worst


def _rk4_scale(lin: Linearised, pd: PD, dt: float, k: int) -> GainScale | None:
    """Largest common Kp, Kd factor in [0, 1] stable at dt on point k (bisection)."""

    def ok(s: float) -> bool:
        mu = continuous_modes(lin.M[k], lin.G[k], pd.scaled(s, s))
        return _rk4_radius(mu, dt) <= 1.0 + RADIUS_TOL

    if not ok(0.0):
        return None
    if ok(1.0):
        return GainScale(1.0, kp=True, kd=True)
    lo, hi = 0.0, 1.0
    for _ in range(BISECT_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return GainScale(lo, kp=True, kd=True)


# -- one loop's verdict and remedy ----------------------------------------------------------


def step_matrix(M: Array, G: Array, pd: PD, dt: float, scheme: Scheme) -> Array:
    """The linear map (q, v) -> (q+, v+) of one step of the linearised loop (for reports)."""
    n = M.shape[0]
    K = G + np.diag(_diag(n, pd, pd.kp))
    D = np.diag(_diag(n, pd, pd.kd + pd.damping))
    eye = np.eye(n)
    if scheme == "rk4":
        Minv = np.linalg.inv(M)
        hA = dt * np.block([[np.zeros((n, n)), eye], [-Minv @ K, -Minv @ D]])
        e2 = np.eye(2 * n)
        out: Array = e2 + hA @ (e2 + hA / 2 @ (e2 + hA / 3 @ (e2 + hA / 4)))
        return out
    Minv = np.linalg.inv(M + dt * D if scheme == "implicit" else M)
    Av = eye - dt * Minv @ D
    Aq = -dt * Minv @ K
    return np.block([[eye + dt * Aq, dt * Av], [Aq, Av]])


def spectral_radius(A: Array) -> float:
    """Largest eigenvalue modulus of A; the discrete loop is stable when it is <= 1."""
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def stable(lin: Linearised, pd: PD, dt: float, scheme: Scheme) -> bool:
    """Whether the loop is stable at dt at every operating point.

    Euler: one batched factorisation of every point's A (what `tune` asks per candidate).
    """
    if scheme == "rk4":
        return all(
            _rk4_radius(continuous_modes(lin.M[k], lin.G[k], pd), dt) <= 1.0 + RADIUS_TOL
            for k in range(len(lin))
        )
    n = lin.M.shape[1]
    c = 1.0 if scheme == "implicit" else -1.0
    diag = 2.0 * c * dt * _diag(n, pd, pd.kd + pd.damping) - dt * dt * _diag(n, pd, pd.kp)
    A = (4.0 + 4.0 * PSD_RTOL) * lin.M - dt * dt * lin.G
    A[:, np.arange(n), np.arange(n)] += diag
    try:
        np.linalg.cholesky(A)
    except np.linalg.LinAlgError:
        return False
    return True


def largest_stable_dt(lin: Linearised, pd: PD, scheme: Scheme, start: float) -> float:
    """Largest dt [s] the loop is stable at on every point (inf if every dt is)."""
    return dt_max_at(lin, pd, scheme, start)[0]


def dt_max_at(lin: Linearised, pd: PD, scheme: Scheme, start: float) -> tuple[float, int]:
    """Largest stable dt [s] over the points, and the index of the point that sets it."""
    if scheme == "rk4":
        modes = [continuous_modes(lin.M[k], lin.G[k], pd) for k in range(len(lin))]
        return _rk4_dt_max(modes, start)
    return _euler_dt_max(lin, pd, scheme, start)


def gain_scale(lin: Linearised, pd: PD, dt: float, scheme: Scheme) -> GainScale | None:
    """Largest stable factor at dt on every point, and which gains it scales.

    At least 1 when the gains are stable; None when no factor >= 0 is (gravity or
    damping alone too stiff).
    """
    if scheme != "rk4":
        return _euler_scale(lin, pd, dt, scheme)
    _, k = dt_max_at(lin, pd, scheme, dt)
    return _rk4_scale(lin, pd, dt, k)
