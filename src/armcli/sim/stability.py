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
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

# The loop counts as stable when the spectral radius is below 1 by this much.
RADIUS_TOL = 1e-12


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
    return float(np.max(np.abs(np.linalg.eigvals(A))))


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

    Uncontrolled joints move freely, so the controlled joints see the
    (controlled, controlled) block of M^-1; implicit damping adds dt*D to the
    controlled diagonal of M before inverting.
    """
    idx = np.asarray(controlled, dtype=int)
    kp_v = np.asarray(Kp, float)
    d_v = np.asarray(Kd, float) + np.asarray(damping, float)
    arm = np.zeros(M_samples[0].shape[0])
    arm[idx] = dt * d_v
    lam_max, lam_imp, rho_exp, rho_imp, worst = 0.0, 0.0, 0.0, 0.0, 0
    for k, M in enumerate(M_samples):
        Minv = np.linalg.inv(M)[np.ix_(idx, idx)]
        Minv_imp = np.linalg.inv(M + np.diag(arm))[np.ix_(idx, idx)]
        lam = float(np.linalg.eigvalsh(0.5 * (Minv + Minv.T))[-1])
        if lam > lam_max:
            lam_max, worst = lam, k
        lam_imp = max(lam_imp, float(np.linalg.eigvalsh(0.5 * (Minv_imp + Minv_imp.T))[-1]))
        rho_exp = max(rho_exp, spectral_radius(update_matrix(Minv, kp_v, d_v, dt)))
        rho_imp = max(rho_imp, spectral_radius(update_matrix(Minv_imp, kp_v, d_v, dt)))
    kp, d = float(kp_v.max()), float(d_v.max())
    a, b = kp * dt * dt * lam_max, d * dt * lam_max
    a_i, b_i = kp * dt * dt * lam_imp, d * dt * lam_imp
    explicit = LoopVerdict(
        rho_exp < 1.0 - RADIUS_TOL, a, b, rho_exp, explicit_dt_max(kp, d, lam_max)
    )
    implicit = LoopVerdict(
        rho_imp < 1.0 - RADIUS_TOL, a_i, b_i, rho_imp, implicit_dt_max(kp, d, lam_max)
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
