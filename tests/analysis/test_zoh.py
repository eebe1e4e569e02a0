"""The held (zero-order-hold) PD(+I) loop against closed forms and a direct iteration.

References: scipy's expm for the batched exponential; for one joint without gravity or
plant damping, Jury's conditions on the exact ZOH of a double integrator (derived in
analysis/zoh.py's docstring: a / 2 < b < 2, a = Kp T² / m, b = Kd T / m), so the largest
stable hold is min(2 Kd / Kp, 2 m / Kd); with an integral term, the scalar loop iterated
step by step from its exact solution over one hold (x += T v + T² u / 2m, v += T u / m).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm as scipy_expm

from armcli.analysis import pdloop, zoh

EXPM_RTOL = 1e-12  # Taylor to 2e-17 per scaled matrix, squared back a few times
# The edge found is where the radius reaches 1 + zoh.RADIUS_TOL (1e-9), not 1: |z| - 1 grows
# like (T Kd / 2m) x the relative excess of T there (>= 1e-3 in these cases), so the edge
# sits up to ~1e-6 relative above the closed form's.
HOLD_RTOL = 1e-5
ITERATIONS = 20_000  # steps of the scalar loop: a radius 1 +- 1e-3 shows as e^+-20
EDGE_FACTORS = (0.97, 1.03)  # holds on either side of the edge, iterated


def _lin(m: float, g: float = 0.0) -> pdloop.Linearised:
    return pdloop.Linearised(np.array([[[m]]]), np.array([[[g]]]))


def _pid(kp: float, kd: float, ki: float = 0.0, damping: float = 0.0) -> zoh.Pid:
    return zoh.Pid.of(pdloop.PD.of([0], [kp], [kd], [damping]), [ki])


@pytest.mark.parametrize("seed", range(5))
def test_batched_expm_equals_scipy(seed: int) -> None:
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(7, 6, 6)) * 10 ** rng.uniform(-3, 1.5, size=(7, 1, 1))
    want = np.array([scipy_expm(a) for a in A])
    assert np.allclose(zoh.expm(A), want, rtol=EXPM_RTOL, atol=EXPM_RTOL * np.abs(want).max())


@pytest.mark.parametrize(
    ("m", "kp", "kd"),
    [(1.8e-3, 50.0, 1.5), (1.8e-3, 50.0, 0.01), (1.0, 1e4, 20.0), (0.05, 3.0, 0.2)],
)
def test_largest_hold_is_jurys_closed_form(m: float, kp: float, kd: float) -> None:
    # a / 2 < b: T < 2 Kd / Kp (the hold's T/2 delay eats Kp T / 2 of damping);
    # b < 2: T < 2 m / Kd (Kd overshoots within one hold)
    want = min(2.0 * kd / kp, 2.0 * m / kd)
    lin, pid = _lin(m), _pid(kp, kd)
    got, _ = zoh.hold_max(zoh.reduce(lin, pid), pid, want / 3.0)
    assert got == pytest.approx(want, rel=HOLD_RTOL)


def _iterate(m: float, kp: float, kd: float, ki: float, hold: float) -> float:
    """|state| after ITERATIONS holds of the scalar PID loop from x = 1 (exact plant)."""
    x, v, i = 1.0, 0.0, 0.0
    for _ in range(ITERATIONS):
        i += ki * hold * -x
        u = -kp * x - kd * v + i
        x, v = x + hold * v + hold * hold * u / (2 * m), v + hold * u / m
        if not math.isfinite(x) or abs(x) > 1e6:
            return math.inf
    return math.hypot(x, v * hold)


@pytest.mark.parametrize(("kp", "kd", "ki"), [(50.0, 1.5, 880.0), (50.0, 1.5, 20_000.0)])
def test_integral_term_edge_agrees_with_the_iterated_loop(kp: float, kd: float, ki: float) -> None:
    m = 1.8e-3  # [kg·m²] the course arm's stretched inertia (lambda_max 554)
    pid = _pid(kp, kd, ki)
    edge, _ = zoh.hold_max(zoh.reduce(_lin(m), pid), pid, 1e-3)
    below, above = (_iterate(m, kp, kd, ki, f * edge) for f in EDGE_FACTORS)
    assert below < 1e-3 and above == math.inf


def test_no_damping_is_unstable_at_every_hold() -> None:
    # b = 0 < a / 2 for any T > 0: the hold's delay makes an undamped PD loop grow, |z|² =
    # 1 + a / 2; only the radius tolerance's sliver is left: 1 + Kp T² / 4m <= 1 + 1e-9
    m, kp = 1e-3, 50.0
    pid = _pid(kp, 0.0)
    edge, _ = zoh.hold_max(zoh.reduce(_lin(m), pid), pid, 1e-3)
    assert edge == pytest.approx(math.sqrt(4 * zoh.RADIUS_TOL * m / kp), rel=1e-3)


def test_points_gravity_tips_are_left_out() -> None:
    # hanging below an unstable equilibrium: Kp 1 against gravity's stiffness -2 (no hold
    # can help there), beside a point the gains hold
    lin = pdloop.Linearised(np.array([[[1.0]], [[1.0]]]), np.array([[[-2.0]], [[0.5]]]))
    pid = _pid(1.0, 0.5)
    h = zoh.reduce(lin, pid)
    assert h.holds(pid).tolist() == [False, True]
    assert zoh.radii(h, pid, 0.01)[0] == 0.0 and zoh.stable(h, pid, 0.01)


def test_free_joints_leave_the_least_inertia() -> None:
    # joint 1 free: the controlled joint sees 1 / (M^-1)_00 = det M / M_11, not M_00
    M = np.array([[[2.0, 0.9], [0.9, 1.0]]])
    lin = pdloop.Linearised(M, np.zeros((1, 2, 2)))
    pid = zoh.Pid.of(pdloop.PD.of([0], [10.0], [0.5], [0.0]))
    m = (2.0 * 1.0 - 0.9 * 0.9) / 1.0
    got, _ = zoh.hold_max(zoh.reduce(lin, pid), pid, 0.01)
    assert got == pytest.approx(min(2 * 0.5 / 10.0, 2 * m / 0.5), rel=HOLD_RTOL)


def test_gain_scale_is_stable_and_largest() -> None:
    m, hold = 1.8e-3, 0.01
    pid = _pid(50.0, 1.5, 880.0)
    h = zoh.reduce(_lin(m), pid)
    s = zoh.gain_scale(h, pid, hold)
    assert s is not None and 0 < s < 1
    assert zoh.stable(h, pid.scaled(s), hold) and not zoh.stable(h, pid.scaled(s * 1.01), hold)
