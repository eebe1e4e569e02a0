"""Sampled-data stability of joint PD control under semi-implicit (symplectic) Euler.

Per mode of the linearised arm, with lambda an eigenvalue of M^-1 [1/(kg·m²)],
D = Kd + damping and the step
    v+ = v + dt * (-Kp q - D v) / m_eff,   q+ = q + dt v+
the update matrix on (q, dt v) is [[1 - a, 1 - b], [-a, 1 - b]] with
a = Kp dt² lambda and b = D dt lambda. Its trace is 2 - a - b and determinant
1 - b; the Jury conditions give stability iff a > 0 and a + 2b < 4.

Explicit damping uses m_eff = 1/lambda. The simulator treats D implicitly by
adding dt*D to the armature (m_eff = 1/lambda + dt D), which turns the
condition into Kp dt² lambda < 4 + 2 D dt lambda: any Kd is then stable and
only Kp is bounded. The worst mode is the largest lambda, so the verdict uses
lambda_max(M^-1) over a sample of the joint range. With unequal gains per
joint the scalar numbers use the largest gains (conservative); the verdict
itself comes from the spectral radius of the full linearised update.

This is the one stability bound of armcli: `check` reports it and `simulate`
refuses what it rejects, with the same tolerance (`RADIUS_TOL`) and the same
"largest stable dt" (bisection on the spectral radius of the real matrices; the
closed forms below are the scalar-mode reference the tests compare it with).
RK4 has no implicit damping; its step map is the 4th-order Taylor polynomial.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

# The loop counts as stable when its step map does not grow: spectral radius <= 1 + RADIUS_TOL.
# Undamped symplectic Euler sits exactly on 1 (a bounded oscillation), so the slack absorbs
# the eigenvalue solver's rounding there.
RADIUS_TOL = 1e-9
BISECT_STEPS = 60  # halvings for the largest stable dt / gain scale (relative error 2^-60)

Scheme = Literal["explicit", "implicit", "rk4"]
"""How the PD loop is stepped: semi-implicit Euler with damping explicit (a torque loop as
in Gazebo's effort controllers) or implicit (armcli's simulator), or RK4 (explicit)."""


@dataclass(frozen=True)
class LoopVerdict:
    """One integration scheme's verdict at the worst sampled configuration."""

    stable: bool
    a: float  # Kp dt² lambda_eff (largest gains)
    b: float  # D dt lambda_eff
    spectral_radius: float  # of the linearised update, worst sample
    dt_max: float  # largest stable dt with these gains [s]


@dataclass(frozen=True)
class StabilityReport:
    """PD stability at the worst sampled configuration, and the gain bounds at `dt`."""

    dt: float  # [s]
    lambda_max: float  # max over samples of lambda_max(M^-1) [1/(kg·m²)]
    q_worst: tuple[float, ...]  # controlled joints at that sample [rad or m]
    kp: float  # largest Kp [N·m/rad]
    d: float  # largest Kd + damping [N·m·s/rad]
    explicit: LoopVerdict
    implicit: LoopVerdict
    kd_max_explicit: float  # largest Kd stable with explicit damping at dt (may be < 0)
    kp_max_implicit: float  # largest Kp stable with implicit damping at dt


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


def update_matrix(
    Minv: NDArray[np.float64], Kp: NDArray[np.float64], D: NDArray[np.float64], dt: float
) -> NDArray[np.float64]:
    """The linear map (q, v) -> (q+, v+) of one semi-implicit Euler step of PD control."""
    n = Minv.shape[0]
    eye = np.eye(n)
    Av = eye - dt * Minv @ np.diag(D)
    Aq = -dt * Minv @ np.diag(Kp)
    return np.block([[eye + dt * Aq, dt * Av], [Aq, Av]])


def spectral_radius(A: NDArray[np.float64]) -> float:
    """Largest eigenvalue modulus of A; the discrete loop is stable when it is <= 1."""
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def is_stable(radius: float) -> bool:
    """The one verdict: the linearised loop does not grow (see RADIUS_TOL)."""
    return radius <= 1.0 + RADIUS_TOL


def step_matrix(
    M: NDArray[np.float64],
    controlled: Sequence[int],
    Kp: NDArray[np.float64],
    D: NDArray[np.float64],
    dt: float,
    scheme: Scheme,
) -> NDArray[np.float64]:
    """The linearised step map on the `controlled` velocity indices of mass matrix M.

    Uncontrolled joints move freely, so the controlled joints see the (controlled,
    controlled) block of M^-1; implicit damping adds dt*D to the controlled diagonal of
    M before inverting. D = Kd + damping [N·m·s/rad].
    """
    idx = np.asarray(controlled, dtype=int)
    if scheme == "implicit":
        arm = np.zeros(M.shape[0])
        arm[idx] = dt * D
        M = M + np.diag(arm)
    Minv = np.linalg.inv(M)[np.ix_(idx, idx)]
    if scheme != "rk4":
        return update_matrix(Minv, Kp, D, dt)
    n = len(idx)
    eye, eye2 = np.eye(n), np.eye(2 * n)
    hA = dt * np.block([[np.zeros((n, n)), eye], [-Minv @ np.diag(Kp), -Minv @ np.diag(D)]])
    out: NDArray[np.float64] = eye2 + hA @ (eye2 + hA / 2 @ (eye2 + hA / 3 @ (eye2 + hA / 4)))
    return out


def worst_radius(
    M_samples: Sequence[NDArray[np.float64]],
    controlled: Sequence[int],
    Kp: NDArray[np.float64],
    D: NDArray[np.float64],
    dt: float,
    scheme: Scheme,
) -> tuple[float, int]:
    """Largest spectral radius over the samples, and the index of that sample."""
    radii = [spectral_radius(step_matrix(M, controlled, Kp, D, dt, scheme)) for M in M_samples]
    k = int(np.argmax(radii))
    return radii[k], k


def _bisect(ok: Callable[[float], bool], lo: float, hi: float) -> float:
    """The edge between ok(lo) and not ok(hi), from below, to BISECT_STEPS halvings."""
    for _ in range(BISECT_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


def largest_stable_dt(
    M_samples: Sequence[NDArray[np.float64]],
    controlled: Sequence[int],
    Kp: NDArray[np.float64],
    D: NDArray[np.float64],
    scheme: Scheme,
    start: float,
) -> float:
    """Largest dt [s] the loop is stable at (inf if every dt is), by bracketing + bisection."""

    def ok(h: float) -> bool:
        return is_stable(worst_radius(M_samples, controlled, Kp, D, h, scheme)[0])

    lo, hi = 0.0, start
    while ok(hi):
        lo, hi = hi, 2.0 * hi
        if hi > 1e6:
            return math.inf
    return _bisect(ok, lo, hi)


def largest_stable_scale(
    M_samples: Sequence[NDArray[np.float64]],
    controlled: Sequence[int],
    Kp: NDArray[np.float64],
    D: NDArray[np.float64],
    dt: float,
    scheme: Scheme,
) -> float:
    """Largest factor s in [0, 1] such that gains s*Kp, s*D are stable at dt."""

    def ok(s: float) -> bool:
        return is_stable(worst_radius(M_samples, controlled, s * Kp, s * D, dt, scheme)[0])

    lo, hi = 0.0, 1.0
    if ok(hi):
        return 1.0
    return _bisect(ok, lo, hi)


def analyse(
    M_samples: Sequence[NDArray[np.float64]],
    q_samples: Sequence[Sequence[float]],
    controlled: Sequence[int],
    Kp: Sequence[float],
    Kd: Sequence[float],
    damping: Sequence[float],
    dt: float,
) -> StabilityReport:
    """Stability of PD on the `controlled` velocity indices over sampled mass matrices.

    The verdicts and largest stable dt come from the spectral radius of the real step
    maps (see `step_matrix`); the scalar numbers (a, b, Kd and Kp bounds) use the
    largest gains and lambda_max, as a conservative explanation of the verdict.
    """
    idx = np.asarray(controlled, dtype=int)
    kp_v = np.asarray(Kp, float)
    d_v = np.asarray(Kd, float) + np.asarray(damping, float)
    arm = np.zeros(M_samples[0].shape[0])
    arm[idx] = dt * d_v
    lam_max, lam_imp, worst = 0.0, 0.0, 0
    for k, M in enumerate(M_samples):
        Minv = np.linalg.inv(M)[np.ix_(idx, idx)]
        Minv_imp = np.linalg.inv(M + np.diag(arm))[np.ix_(idx, idx)]
        lam = float(np.linalg.eigvalsh(0.5 * (Minv + Minv.T))[-1])
        if lam > lam_max:
            lam_max, worst = lam, k
        lam_imp = max(lam_imp, float(np.linalg.eigvalsh(0.5 * (Minv_imp + Minv_imp.T))[-1]))
    rho_exp = worst_radius(M_samples, controlled, kp_v, d_v, dt, "explicit")[0]
    rho_imp = worst_radius(M_samples, controlled, kp_v, d_v, dt, "implicit")[0]
    kp, d = float(kp_v.max()), float(d_v.max())
    a, b = kp * dt * dt * lam_max, d * dt * lam_max
    a_i, b_i = kp * dt * dt * lam_imp, d * dt * lam_imp
    explicit = LoopVerdict(
        is_stable(rho_exp),
        a,
        b,
        rho_exp,
        largest_stable_dt(M_samples, controlled, kp_v, d_v, "explicit", dt),
    )
    implicit = LoopVerdict(
        is_stable(rho_imp),
        a_i,
        b_i,
        rho_imp,
        largest_stable_dt(M_samples, controlled, kp_v, d_v, "implicit", dt),
    )
    return StabilityReport(
        dt=dt,
        lambda_max=lam_max,
        q_worst=tuple(float(x) for x in q_samples[worst]),
        kp=kp,
        d=d,
        explicit=explicit,
        implicit=implicit,
        kd_max_explicit=(4.0 - a) / (2.0 * dt * lam_max) - float(np.max(damping)),
        kp_max_implicit=(4.0 + 2.0 * b) / (dt * dt * lam_max),
    )
