"""Sampled-data PD stability against independent references: the textbook mass matrix
of a planar two-link arm, and brute-force iteration of the integrator itself."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from armcli.analysis import pdloop
from armcli.analysis import stability as stab
from armcli.analysis import verdict as verdicts
from armcli.errors import UnstableLoopError
from armcli.robot.file import robot_of
from armcli.robot.model import Robot
from armcli.sim.simulate import SimConfig, check_stability
from tests.helpers import DEFAULT_SPEC, load_robot, spec_file

# The course arm (specs/my_robot.yaml): two solid cylinders r = 0.02 m, l = 0.3 m,
# m = 0.3 kg, hinged at one end, both joints about y; gains Kp = 50, Kd = 5, joint
# damping 0.1, dt = 1 ms.
M_LINK, R_LINK, L_LINK = 0.3, 0.02, 0.3
KP, KD, DAMPING, DT = 50.0, 5.0, 0.1, 1e-3
# The issue quotes lambda_max(M^-1) "about 554" at q2 = 0.
ISSUE_LAMBDA = 554.0
LAMBDA_RTOL = 1e-3
STEPS = 20_000
DIVERGED = 1e6  # stop iterating once the error has grown this much


def two_link_mass_matrix(q2: float) -> np.ndarray:
    """Planar two-link arm (Spong, Robot Modeling and Control, eq. 7.87), links as rods
    with their centre of mass at mid-length and I about it from the cylinder formula."""
    m1 = m2 = M_LINK
    l1, lc1, lc2 = L_LINK, L_LINK / 2, L_LINK / 2
    I1 = I2 = M_LINK * (3 * R_LINK**2 + L_LINK**2) / 12
    c2 = math.cos(q2)
    d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
    d12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
    d22 = m2 * lc2**2 + I2
    return np.array([[d11, d12], [d12, d22]])


def simulate(M: np.ndarray, kp: float, d: float, dt: float, implicit: bool) -> float:
    """Iterate the semi-implicit Euler PD loop from a small error; return |x_end| / |x_0|."""
    n = M.shape[0]
    Kp, D = kp * np.eye(n), d * np.eye(n)
    A_inv = np.linalg.inv(M + dt * D if implicit else M)
    q, v = np.full(n, 1e-3), np.zeros(n)
    ratio = 1.0
    for _ in range(STEPS):
        v = v + dt * A_inv @ (-Kp @ q - D @ v)
        q = q + dt * v
        ratio = float(np.hypot(np.linalg.norm(q), dt * np.linalg.norm(v)) / 1e-3 / math.sqrt(n))
        if ratio > DIVERGED:
            break
    return ratio


def test_textbook_arm_gives_the_issue_lambda() -> None:
    lam = np.linalg.eigvalsh(np.linalg.inv(two_link_mass_matrix(0.0)))[-1]
    assert lam == pytest.approx(ISSUE_LAMBDA, rel=LAMBDA_RTOL)


@pytest.mark.parametrize("a", [0.01, 0.5, 1.5, 3.0, 3.9])
@pytest.mark.parametrize("b", [0.1, 0.9, 1.4, 1.9])
def test_jury_condition_matches_iterating_the_scalar_mode(a: float, b: float) -> None:
    # One mode with lambda = 1: Kp dt² = a and D dt = b with dt = 1.
    M = np.eye(1)
    grows = simulate(M, kp=a, d=b, dt=1.0, implicit=False) > 1.0
    assert stab.explicit_stable(a, b) == (not grows)


def _lin(*Ms: np.ndarray) -> pdloop.Linearised:
    """Mass matrices without gravity (the textbook arm lies in a horizontal plane)."""
    return pdloop.Linearised(np.array(Ms), np.zeros((len(Ms), *Ms[0].shape)))


def _pd(kp: float, kd: float, damping: float, n: int = 2) -> pdloop.PD:
    return pdloop.PD.of(range(n), [kp] * n, [kd] * n, [damping] * n)


def test_seed_arm_explicit_diverges_implicit_converges() -> None:
    Ms = [two_link_mass_matrix(q2) for q2 in np.linspace(0, math.pi / 2, 5)]
    qs = [[0.0, q2] for q2 in np.linspace(0, math.pi / 2, 5)]
    rep = verdicts.analyse(_lin(*Ms), qs, _pd(KP, KD, DAMPING), DT)
    assert rep.lambda_max == pytest.approx(ISSUE_LAMBDA, rel=LAMBDA_RTOL)
    assert rep.q_worst == (0.0, 0.0)  # lambda_max(M^-1) is largest with the arm stretched
    # b = (Kd + damping) dt lambda = 5.1e-3 * 554 = 2.83 > 2: explicit loop diverges.
    assert rep.explicit.b == pytest.approx((KD + DAMPING) * DT * ISSUE_LAMBDA, rel=LAMBDA_RTOL)
    assert not rep.explicit.stable and rep.implicit.stable
    M0 = two_link_mass_matrix(0.0)
    assert simulate(M0, KP, KD + DAMPING, DT, implicit=False) > 1e3
    assert simulate(M0, KP, KD + DAMPING, DT, implicit=True) < 1.0


def test_suggested_bounds_are_the_stability_edge() -> None:
    M0 = two_link_mass_matrix(0.0)
    lam = float(np.linalg.eigvalsh(np.linalg.inv(M0))[-1])
    d = KD + DAMPING
    dt_max = stab.explicit_dt_max(KP, d, lam)
    assert simulate(M0, KP, d, 0.98 * dt_max, implicit=False) < 1.0
    assert simulate(M0, KP, d, 1.02 * dt_max, implicit=False) > 1.0
    rep = verdicts.analyse(_lin(M0), [[0.0, 0.0]], _pd(KP, KD, DAMPING), DT)
    kd_max = rep.kd_max_explicit
    assert kd_max is not None and rep.kp_max_implicit is not None
    assert simulate(M0, KP, 0.98 * kd_max + DAMPING, DT, implicit=False) < 1.0
    assert simulate(M0, KP, 1.02 * kd_max + DAMPING, DT, implicit=False) > 1.0
    # With implicit damping only Kp is bounded.
    kp_max = rep.kp_max_implicit
    assert simulate(M0, 0.98 * kp_max, d, DT, implicit=True) < 1.0
    assert simulate(M0, 1.02 * kp_max, d, DT, implicit=True) > 1.0


def test_pinocchio_crba_matches_the_textbook_matrix(root) -> None:
    import pinocchio as pin

    robot = load_robot(root / "urdf" / "standalone_arm.urdf")
    model, data = robot.model, robot.data
    for q2 in (0.0, 0.7, math.pi / 2):
        q = robot.q({"arm_base_forearm_joint": 0.3, "forearm_hand_joint": q2})
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        np.testing.assert_allclose(M, two_link_mass_matrix(q2), rtol=1e-9)


# -- one bound for `check` and `simulate` ----------------------------------------------------


@pytest.fixture(scope="module")
def seed_arm() -> Robot:
    file = spec_file(DEFAULT_SPEC)
    return robot_of(file, file.arm)


def _sweep() -> list[tuple[float, float, float, float]]:
    """(Kp, Kd, damping, dt) around the seed arm's stability edge, undamped cases included."""
    rng = np.random.default_rng(7)
    cases = [(KP, 0.0, 0.0, DT), (4e5, 0.0, 0.0, DT), (KP, KD, DAMPING, DT), (1e3, 0.0, 0.0, 0.01)]
    for _ in range(40):
        kp = float(10 ** rng.uniform(0, 6))
        kd = float(rng.choice([0.0, 10 ** rng.uniform(-2, 2)]))
        d = float(rng.choice([0.0, 0.1]))
        cases.append((kp, kd, d, float(10 ** rng.uniform(-4, -1.5))))
    return cases


@pytest.mark.parametrize(("kp", "kd", "damping", "dt"), _sweep())
def test_check_verdict_equals_simulate_acceptance(
    seed_arm: Robot, kp: float, kd: float, damping: float, dt: float
) -> None:
    """`check`'s implicit-loop verdict and `simulate`'s refusal come from one bound."""
    arm = seed_arm.with_limits(damping=np.full(2, damping))
    configs = np.array([[a, b] for a in (0.0, 0.8, 1.57) for b in (0.0, 0.8, 1.57)])
    data = arm.model.createData()
    Ms = []
    for q in configs:
        M = pin.crba(arm.model, data, q)
        Ms.append(np.triu(M) + np.triu(M, 1).T)
    G = [pin.computeGeneralizedGravityDerivatives(arm.model, data, q) for q in configs]
    lin = pdloop.Linearised(np.array(Ms), np.array([0.5 * (g + g.T) for g in G]))
    rep = verdicts.analyse(lin, configs.tolist(), _pd(kp, kd, damping), dt)
    cfg = SimConfig(kp=np.full(2, kp), kd=np.full(2, kd), dt=dt)
    try:
        check_stability(arm, cfg, configs)
        accepted = True
    except UnstableLoopError:
        accepted = False
    assert rep.implicit.stable == accepted


def test_undamped_loop_is_marginal_and_accepted() -> None:
    """No damping: symplectic Euler keeps |eigenvalues| = 1 (a bounded oscillation) below the
    Jury edge a < 4, so both commands accept it, and iterating it neither grows nor decays."""
    M = two_link_mass_matrix(0.0)
    rep = verdicts.analyse(_lin(M), [[0.0, 0.0]], _pd(KP, 0.0, 0.0), DT)
    assert rep.implicit.stable and rep.explicit.stable
    assert rep.implicit.spectral_radius == pytest.approx(1.0, abs=1e-6)
    assert simulate(M, KP, 0.0, DT, implicit=True) < 1.5  # bounded: no growth


def test_largest_stable_dt_matches_the_closed_form() -> None:
    """Bisection on the real step map equals the scalar Jury edge for equal gains."""
    M = two_link_mass_matrix(0.0)
    lam = float(np.linalg.eigvalsh(np.linalg.inv(M))[-1])
    d = KD + DAMPING
    dt_exp = stab.largest_stable_dt(_lin(M), _pd(KP, KD, DAMPING), "explicit", DT)
    assert dt_exp == pytest.approx(stab.explicit_dt_max(KP, d, lam), rel=1e-9)
