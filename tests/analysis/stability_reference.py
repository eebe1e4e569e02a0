"""The eigenvalue computation armcli used before the A >= 0 bound, kept as the reference.

Spectral radius of the real 2n x 2n step map of semi-implicit Euler at every sample, and
bisection on it for the largest stable dt and gain scale (armcli.analysis.stability up to
commit 27d99ba, extended with gravity's stiffness: K = Kp + G). Slow (O(n³) on 2n per
probe, 60 probes per bisection) and independent of the Cholesky bound it checks.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

RADIUS_TOL = 1e-9
BISECT_STEPS = 60


def step_matrix(
    M: np.ndarray,
    G: np.ndarray,
    idx: Sequence[int],
    kp: np.ndarray,
    D: np.ndarray,
    dt: float,
    scheme: str,
) -> np.ndarray:
    """One Euler step's linear map on the controlled joints' (q, v).

    Free joints are eliminated as before: the controlled joints see the (controlled,
    controlled) block of M^-1 (implicit damping adds dt D to M's controlled diagonal first);
    G is taken on the controlled block, so callers give G = 0 when some joint is free.
    """
    ix = np.asarray(idx, dtype=int)
    arm = np.zeros(M.shape[0])
    if scheme == "implicit":
        arm[ix] = dt * D
    Minv = np.linalg.inv(M + np.diag(arm))[np.ix_(ix, ix)]
    K = np.diag(kp) + G[np.ix_(ix, ix)]
    eye = np.eye(len(ix))
    Av = eye - dt * Minv @ np.diag(D)
    Aq = -dt * Minv @ K
    return np.block([[eye + dt * Aq, dt * Av], [Aq, Av]])


def radius(A: np.ndarray) -> float:
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def worst_radius(Ms, Gs, idx, kp, D, dt, scheme) -> float:
    return max(
        radius(step_matrix(M, G, idx, kp, D, dt, scheme)) for M, G in zip(Ms, Gs, strict=True)
    )


def _bisect(ok: Callable[[float], bool], lo: float, hi: float) -> float:
    for _ in range(BISECT_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


def largest_stable_dt(Ms, Gs, idx, kp, D, scheme, start) -> float:
    def ok(h: float) -> bool:
        return worst_radius(Ms, Gs, idx, kp, D, h, scheme) <= 1.0 + RADIUS_TOL

    lo, hi = 0.0, start
    while ok(hi):
        lo, hi = hi, 2.0 * hi
        if hi > 1e6:
            return float("inf")
    return _bisect(ok, lo, hi)


def largest_stable_scale(Ms, Gs, idx, kp, kd, damping, dt, scheme, kp_too, kd_too) -> float:
    """Largest s in [0, 1] with s Kp (when `kp_too`) and s Kd (when `kd_too`) stable at dt."""

    def ok(s: float) -> bool:
        D = (s * kd if kd_too else kd) + damping
        return (
            worst_radius(Ms, Gs, idx, s * kp if kp_too else kp, D, dt, scheme) <= 1.0 + RADIUS_TOL
        )

    return 1.0 if ok(1.0) else _bisect(ok, 0.0, 1.0)
