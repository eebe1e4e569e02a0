"""Gravity's stiffness in the stability bound (issue 24), against the closed-form pendulum.

A pendulum of mass m, centre of mass l below the hinge and inertia I about it, under PD
gains Kp, Kd and gravity g, linearised at angle theta (0 = hanging), is the scalar mode

    I x'' + D x' + k x = 0,   k = Kp + m g l cos(theta).

Semi-implicit Euler on it is stable iff k dt² <= 4 I + 2 c D dt (c = +1 with damping
implicit, -1 explicit), the Jury condition of the 2x2 step map: the largest stable dt is
`implicit_dt_max(k, D, 1/I)` / `explicit_dt_max`. The bound must reproduce this through
Pinocchio's model of the URDF, and the real simulator must stay bounded below it and
blow up above it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.analysis import pdloop
from armcli.analysis import stability as stab
from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.sim.simulate import SimConfig, simulate, simulated
from armcli.spec.load import load_spec
from armcli.trajectory.message import loads_trajectory
from armcli.trajectory.reference import build_reference
from armcli.urdf.read import read_urdf
from tests.helpers import FIXTURES, load_robot

PENDULUM = FIXTURES / "stability" / "pendulum_1cm.urdf"
# The fixture's numbers (see its header): bob mass, centre-of-mass depth, inertia about the
# hinge = m l² + the sphere's own 2/5 m r² (given in the URDF as 1.6e-7).
MASS, DEPTH, G0 = 0.1, 0.01, 9.81
INERTIA = MASS * DEPTH**2 + 1.6e-7
RTOL = 1e-9  # Pinocchio's M and dg/dq against the formulas
DT_RTOL = 1e-8  # bisection + PSD_RTOL slack
SWING_START = 0.05  # [rad]
SWING_RTOL = 0.02  # the linear invariant against the nonlinear pendulum at ~0.16 rad


@pytest.fixture(scope="module")
def model():
    return load_robot(PENDULUM)


def _lin(model, thetas):
    return pdloop.linearise(model, [np.array([t]) for t in thetas])


@pytest.mark.parametrize("theta", [0.0, 0.7, 1.5, 2.5, -3.0])
def test_pinocchio_gives_the_pendulum_inertia_and_stiffness(model, theta: float) -> None:
    lin = _lin(model, [theta])
    assert lin.M[0, 0, 0] == pytest.approx(INERTIA, rel=RTOL)
    assert lin.G[0, 0, 0] == pytest.approx(MASS * G0 * DEPTH * math.cos(theta), rel=RTOL)


@pytest.mark.parametrize("kp", [0.0, 0.001, 0.01, 0.1])
@pytest.mark.parametrize("kd", [0.0, 1e-5, 1e-4])
@pytest.mark.parametrize("scheme", ["implicit", "explicit"])
def test_largest_stable_dt_is_the_closed_form(model, kp: float, kd: float, scheme: str) -> None:
    """Over the whole range the hanging pose is the stiffest: k = Kp + m g l."""
    lin = _lin(model, np.linspace(-3.0, 3.0, 13))
    pd = pdloop.PD.of([0], [kp], [kd], [0.0])
    k = kp + MASS * G0 * DEPTH
    bound = stab.implicit_dt_max if scheme == "implicit" else stab.explicit_dt_max
    expected = bound(k, kd, 1.0 / INERTIA)
    got = stab.largest_stable_dt(lin, pd, scheme, 0.01)  # type: ignore[arg-type]
    assert got == pytest.approx(expected, rel=DT_RTOL)


def test_without_gravity_the_bound_ignores_it(model) -> None:
    """Gravity compensation cancels g(q) at the same q: only Kp is left."""
    lin = pdloop.linearise(model, [np.zeros(1)], gravity=False)
    pd = pdloop.PD.of([0], [0.001], [0.0], [0.0])
    expected = stab.implicit_dt_max(0.001, 0.0, 1.0 / INERTIA)
    assert stab.largest_stable_dt(lin, pd, "implicit", 0.01) == pytest.approx(expected, rel=DT_RTOL)


def _swing(model, dt: float, seconds: float) -> np.ndarray:
    """The real simulator (semi-implicit Euler, both engines' step) from 0.05 rad, Kp 0.001."""
    arm = simulated(model)
    traj = loads_trajectory(
        "joint_names: [swing_joint]\npoints: [{positions: [0.0], time_from_start: 0.01}]",
        {"swing_joint": (-3.0, 3.0)},
    )
    q0 = np.array([SWING_START])
    ref = build_reference(traj, arm.names, q0)
    cfg = SimConfig(kp=np.array([0.001]), kd=np.zeros(1), dt=dt, integrator="euler")
    return simulate(arm, ref, q0, seconds, cfg).q[:, 0]


def test_the_simulator_swings_below_the_bound_and_bangs_above(model) -> None:
    """The issue's case: at dt = 0.1 s the pendulum bangs between the stops; just below the
    bound it keeps swinging, bounded. Symplectic Euler on I x'' = -k x conserves
    x² - dt x v + v² / w² (w² = k / I), so from rest at x0 the swing peaks at
    x0 / sqrt(1 - (w dt / 2)²) and never grows."""
    k = 0.001 + MASS * G0 * DEPTH
    edge = stab.implicit_dt_max(k, 0.0, 1.0 / INERTIA)
    dt = 0.95 * edge
    below = np.abs(_swing(model, dt, 400 * edge))
    peak = SWING_START / math.sqrt(1.0 - (k / INERTIA) * dt * dt / 4.0)
    assert np.max(below) <= (1.0 + SWING_RTOL) * peak
    half = below.size // 2
    assert np.max(below[half:]) <= (1.0 + SWING_RTOL) * np.max(below[:half])  # no growth
    above = _swing(model, 0.1, 20.0)
    assert np.max(np.abs(above)) > 2.9  # reaches the +-3 rad stops


def test_check_refuses_the_issues_pendulum() -> None:
    """`check` with the pendulum's spec (Kp 0.001, Kd 0, dt 0.1 s): an error for the
    simulator's loop, whose remedy is a time step (no lower gain helps against gravity)."""
    spec = load_spec(FIXTURES / "stability" / "pendulum_1cm.yaml")
    result = check_urdf(read_urdf(PENDULUM), CheckOptions(spec=spec))
    (f,) = [f for f in result.findings if f.rule == "pd-unstable"]
    assert f.severity == "error"
    edge = stab.implicit_dt_max(0.001 + MASS * G0 * DEPTH, 0.0, 1.0 / INERTIA)
    assert f.values["dt_max"] == pytest.approx(edge, rel=DT_RTOL)
    assert f.fix == {"dt": 0.055}  # 0.9 x 0.0613, rounded down to 2 digits
