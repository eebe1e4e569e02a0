"""Model-based start gains against closed forms on a single-link pendulum (no gravity
torque: the joint axis is vertical), so the loop is m q'' + kd q' + kp q = kp q_ref."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.robot.model import Robot
from armcli.sim.simulate import SimConfig, SimResult, simulate, simulated
from armcli.trajectory.reference import Reference
from armcli.tune.model_gains import STABILITY_MARGIN, start_gains
from armcli.tune.objective import overshoot
from tests.helpers import FIXTURES, load_robot

URDF = FIXTURES / "tune" / "pendulum.urdf"
M_PENDULUM = 0.01 + 2.0 * 0.5**2  # [kg·m²] izz + m r² from the fixture
STEP = 0.5  # [rad]
DT_FINE = 1e-4  # [s] small enough that the discrete loop matches the continuous one
OVERSHOOT_TOL = 0.005  # absolute, on the overshoot fraction (Euler error ~ wn dt = 1e-3)
RISE_REL_TOL = 0.01  # relative, on the 0 -> 100 % rise time
GAIN_REL_TOL = 1e-9


@pytest.fixture(scope="module")
def arm() -> Robot:
    return simulated(load_robot(URDF))


def step_response(
    arm: Robot, kp: float, kd: float, duration: float
) -> tuple[np.ndarray, np.ndarray, SimResult]:
    ref = Reference(knots=np.array([0.0]), coeffs=np.zeros((0, 6, 1)), final=np.array([STEP]))
    cfg = SimConfig(np.array([kp]), np.array([kd]), DT_FINE)
    res = simulate(arm, ref, np.zeros(1), duration, cfg)
    return res.t, res.q[:, 0], res


@pytest.mark.parametrize("zeta, wn", [(0.5, 10.0), (0.3, 20.0)])
def test_underdamped_step_matches_closed_form(arm: Robot, zeta: float, wn: float) -> None:
    start = start_gains(arm, dt=DT_FINE, loop="implicit", zeta=zeta, wn_target=wn,
                        steps=np.array([STEP]))  # fmt: skip
    row = start.rows[0]
    assert row.binding == "target"
    # kp = m wn², kd = 2 zeta wn m (the definitions in model_gains' docstring).
    assert row.kp == pytest.approx(M_PENDULUM * wn**2, rel=GAIN_REL_TOL)
    assert row.kd == pytest.approx(2 * zeta * wn * M_PENDULUM, rel=GAIN_REL_TOL)
    t, q, res = step_response(arm, row.kp, row.kd, duration=8.0 / (zeta * wn))
    wd = wn * math.sqrt(1 - zeta**2)
    # Second-order step response: overshoot exp(-pi zeta / sqrt(1 - zeta²)),
    # first reaching the target at t_r = (pi - acos zeta) / wd.
    expected_os = math.exp(-math.pi * zeta / math.sqrt(1 - zeta**2))
    expected_rise = (math.pi - math.acos(zeta)) / wd
    measured_os = (q.max() - STEP) / STEP
    rise = t[np.argmax(q >= STEP)]
    assert measured_os == pytest.approx(expected_os, abs=OVERSHOOT_TOL)
    assert rise == pytest.approx(expected_rise, rel=RISE_REL_TOL)
    assert overshoot(res, 0.0)[0] == pytest.approx(measured_os, abs=1e-12)


def test_critical_damping_does_not_overshoot(arm: Robot) -> None:
    start = start_gains(arm, dt=DT_FINE, loop="implicit", zeta=1.0, wn_target=10.0,
                        steps=np.array([STEP]))  # fmt: skip
    _, q, _ = step_response(arm, start.kp[0], start.kd[0], duration=2.0)
    # zeta = 1: q(t) = STEP (1 - (1 + wn t) e^(-wn t)) never exceeds STEP.
    assert q.max() <= STEP * (1 + OVERSHOOT_TOL)
    # ... and reaches 1 - 5 e^-4 = 90.8 % of it at t = 4 / wn.
    k = round(0.4 / DT_FINE)
    assert q[k] / STEP == pytest.approx(1 - 5 * math.exp(-4), abs=OVERSHOOT_TOL)


@pytest.mark.parametrize(
    "loop, x_max",
    [
        # Jury bounds of one mode with kp = m wn², D = 2 zeta wn m at zeta = 1, x = wn h:
        # implicit damping: x² < 4 + 4x -> x < 2 + 2 sqrt(2); explicit: x² + 4x < 4.
        ("implicit", 2.0 + 2.0 * math.sqrt(2.0)),
        ("explicit", 2.0 * math.sqrt(2.0) - 2.0),
    ],
)
def test_stability_cap_is_the_jury_bound(arm: Robot, loop: str, x_max: float) -> None:
    dt = 0.01
    start = start_gains(arm, dt=dt, loop=loop, zeta=1.0, wn_target=1e4, steps=np.array([STEP]))
    row = start.rows[0]
    assert row.binding == "stability"
    assert row.wn == pytest.approx(x_max / (STABILITY_MARGIN * dt), rel=1e-6)


def test_effort_cap(arm: Robot) -> None:
    effort = 20.0  # [N·m]
    limited = arm.with_limits(effort=np.array([effort]))
    start = start_gains(limited, dt=1e-3, loop="implicit", zeta=1.0, wn_target=1e3,
                        steps=np.array([STEP]))  # fmt: skip
    # No gravity torque: kp * step = effort exactly.
    assert start.rows[0].binding == "effort"
    assert start.kp[0] == pytest.approx(effort / STEP, rel=1e-9)
    _, _, res = step_response(limited, start.kp[0], start.kd[0], duration=1.0)
    assert np.max(np.abs(res.tau)) <= effort * (1 + 1e-12)
