"""The Cholesky bound (A >= 0) equals the eigenvalue computation it replaced, on small cases.

Seeded random arms of 1-4 joints (free joints included), gains from undamped to heavily
damped, gravity's stiffness positive semidefinite, time steps on both sides of the edge;
the reference is tests/analysis/stability_reference.py (spectral radius of the real step map).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.analysis import pdloop
from armcli.analysis import stability as stab
from tests.analysis import stability_reference as ref

CASES = 60
NEAR_EDGE = 1e-6  # verdicts are compared only where the reference radius is this far from 1
DT_RTOL = 1e-7  # bisection to 2^-60 on both sides; the reference's eigvals limit agreement
SCALE_ATOL = 1e-7


def _case(seed: int) -> tuple[pdloop.Linearised, pdloop.PD, float]:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 5))
    free = n > 1 and rng.random() < 0.3
    idx = list(range(n - 1)) if free else list(range(n))
    B = rng.normal(size=(n, n)) * 10 ** rng.uniform(-2, 0, size=n)
    M = B @ B.T + np.diag(10 ** rng.uniform(-4, -1, size=n))
    G = np.zeros((n, n))
    if not free and rng.random() < 0.5:
        C = rng.normal(size=(n, n)) * 10 ** rng.uniform(-2, 1)
        G = C @ C.T
    m = len(idx)
    kp = 10 ** rng.uniform(-1, 4, size=m)
    kd = np.where(rng.random(m) < 0.3, 0.0, 10 ** rng.uniform(-3, 1, size=m))
    damping = np.where(rng.random(m) < 0.5, 0.0, 10 ** rng.uniform(-3, 0, size=m))
    lam = float(np.linalg.eigvalsh(np.linalg.inv(M))[-1])
    # around the scalar edge of the stiffest mode, so both verdicts occur
    edge = stab.implicit_dt_max(float(kp.max()), float((kd + damping).max()), lam)
    dt = float(min(edge, 1.0) * 10 ** rng.uniform(-0.7, 0.5))
    lin = pdloop.Linearised(M[None], G[None])
    return lin, pdloop.PD.of(idx, kp, kd, damping), dt


def _ref_args(lin: pdloop.Linearised, pd: pdloop.PD) -> tuple:
    return list(lin.M), list(lin.G), list(pd.idx), pd.kp, pd.kd + pd.damping


@pytest.mark.parametrize("seed", range(CASES))
@pytest.mark.parametrize("scheme", ["implicit", "explicit"])
def test_verdict_equals_the_eigenvalue_reference(seed: int, scheme: pdloop.Scheme) -> None:
    lin, pd, dt = _case(seed)
    Ms, Gs, idx, kp, D = _ref_args(lin, pd)
    rho = ref.worst_radius(Ms, Gs, idx, kp, D, dt, scheme)
    if abs(rho - 1.0) < NEAR_EDGE and rho > 1.0:
        pytest.skip("on the edge")
    assert stab.stable(lin, pd, dt, scheme) == (rho <= 1.0 + ref.RADIUS_TOL)


@pytest.mark.parametrize("seed", range(CASES))
@pytest.mark.parametrize("scheme", ["implicit", "explicit"])
def test_largest_stable_dt_equals_the_eigenvalue_reference(
    seed: int, scheme: pdloop.Scheme
) -> None:
    lin, pd, dt = _case(seed)
    Ms, Gs, idx, kp, D = _ref_args(lin, pd)
    expected = ref.largest_stable_dt(Ms, Gs, idx, kp, D, scheme, dt)
    got = stab.largest_stable_dt(lin, pd, scheme, dt)
    if math.isinf(expected):
        assert math.isinf(got)
    else:
        assert got == pytest.approx(expected, rel=DT_RTOL)


@pytest.mark.parametrize("seed", range(CASES))
@pytest.mark.parametrize("scheme", ["implicit", "explicit"])
def test_gain_scale_equals_the_eigenvalue_reference(seed: int, scheme: pdloop.Scheme) -> None:
    lin, pd, dt = _case(seed)
    Ms, Gs, idx, _, _ = _ref_args(lin, pd)
    got = stab.gain_scale(lin, pd, dt, scheme)
    # implicit damping scales Kp alone; explicit Kd alone when that can be stable, else both
    kp_too, kd_too = (got.kp, got.kd) if got is not None else (True, scheme != "implicit")
    assert kp_too or scheme != "implicit"
    expected = ref.largest_stable_scale(
        Ms, Gs, idx, pd.kp, pd.kd, pd.damping, dt, scheme, kp_too, kd_too
    )
    got_01 = 0.0 if got is None else min(got.factor, 1.0)
    assert got_01 == pytest.approx(expected, abs=SCALE_ATOL, rel=DT_RTOL)
    if got is not None and got.kp and got.kd and scheme == "explicit":
        # Kd alone could not make it: even Kd = 0 is unstable at this dt
        assert ref.largest_stable_scale(
            Ms, Gs, idx, pd.kp, pd.kd, pd.damping, dt, scheme, False, True
        ) == 0.0 or not np.any(pd.kd > 0)


@pytest.mark.parametrize("a", [0.01, 0.5, 1.5, 3.0, 3.9, 4.1, 6.0])
@pytest.mark.parametrize("b", [0.0, 0.1, 0.9, 1.4, 1.9, 2.1])
def test_one_joint_is_the_jury_condition(a: float, b: float) -> None:
    """lambda = 1, dt = 1: Kp = a and D = b; explicit a + 2b <= 4, implicit a - 2b <= 4."""
    lin = pdloop.Linearised(np.eye(1)[None], np.zeros((1, 1, 1)))
    pd = pdloop.PD.of([0], [a], [b], [0.0])
    if a + 2 * b != 4.0:
        assert stab.stable(lin, pd, 1.0, "explicit") == (a + 2 * b < 4.0)
    assert stab.stable(lin, pd, 1.0, "implicit") == (a - 2 * b < 4.0)
    assert stab.largest_stable_dt(lin, pd, "explicit", 1.0) == pytest.approx(
        stab.explicit_dt_max(a, b, 1.0), rel=1e-9
    )
    assert stab.largest_stable_dt(lin, pd, "implicit", 1.0) == pytest.approx(
        stab.implicit_dt_max(a, b, 1.0), rel=1e-9
    )
