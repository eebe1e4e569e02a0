"""Tracking metrics against the closed-form discrete solutions of two one-joint runs, and
joint-state sampling at the publisher rate."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from armcli.robot.model import Robot
from armcli.sim import rollout as ro
from armcli.sim.report import SETTLE_TOL, joint_metrics
from armcli.sim.simulate import SimConfig, SimResult, plant_of, simulate
from armcli.sim.states import sample_states, sample_steps, states_bytes
from armcli.trajectory.reference import Reference
from tests.sim.engines import hold, require_native

DT = 1e-3
INERTIA = 0.25  # [kg·m²] about the joint axis


def wheel(damping: float) -> Robot:
    """A joint about the vertical axis (gravity exerts no torque): inertia INERTIA."""
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "wheel")
    model.appendBodyToJoint(jid, pin.Inertia(1.0, np.zeros(3), np.diag([1.0, 1.0, INERTIA])),
                            pin.SE3.Identity())  # fmt: skip
    one = np.ones(1)
    return Robot(model).with_limits(
        lower=-1e3 * one,
        upper=1e3 * one,
        effort=np.inf * one,
        velocity=1e3 * one,
        damping=damping * one,
        friction=0 * one,
    )


def _coast(arm: Robot, q0: float, v0: float, steps: int) -> SimResult:
    """No gains, the reference held at 0, from (q0, v0): the error is the position."""
    require_native()
    cfg = SimConfig(np.zeros(1), np.zeros(1), dt=DT)
    r = ro.run(plant_of(arm, cfg), hold(np.zeros(1)), np.array([q0]), np.array([v0]), steps,
               settle_tol=SETTLE_TOL)  # fmt: skip
    tr = r.trace
    return SimResult(arm.names, steps, DT, "euler", tr.step, tr.step * DT, tr.q, tr.v,
                     tr.q_ref, tr.v_ref, tr.tau, tr.saturated, tr.stop, r.stats, SETTLE_TOL,
                     0.0)  # fmt: skip


def test_ramp_rms_max_final() -> None:
    """Free rotation at v0 away from a reference held at 0: e_k = v0 k dt exactly."""
    steps, v0 = 2000, 0.5
    res = _coast(wheel(0.0), 0.0, v0, steps)
    np.testing.assert_allclose(res.q[:, 0], v0 * DT * np.arange(steps + 1), rtol=1e-12)
    m = joint_metrics(res, t_end=0.0)[0]
    # closed form: sum of k² for k = 0..N is N(N+1)(2N+1)/6, over N + 1 states
    rms = v0 * DT * math.sqrt(steps * (2 * steps + 1) / 6)
    assert m.rms_error == pytest.approx(rms, rel=1e-12)
    assert m.max_error == pytest.approx(v0 * DT * steps, rel=1e-12)
    assert m.final_error == pytest.approx(v0 * DT * steps, rel=1e-12)
    assert m.settle_time is None  # outside the band at the end


def test_settle_time_of_a_damped_coast() -> None:
    """Viscous damping D only: implicit Euler gives v_k = v0 r^k with r = I / (I + dt D);
    from q0 = -A r, A = dt v0 / (1 - r), the error is e_k = -A r^(k+1). It is outside the
    band while r^(k+1) > SETTLE_TOL / A: the last such k is ceil(x) - 2, x = log(tol/A)/log r."""
    D, v0, steps, t_end = 0.5, 2.0, 3000, 0.3
    r = INERTIA / (INERTIA + DT * D)
    A = DT * v0 / (1.0 - r)
    res = _coast(wheel(D), -A * r, v0, steps)
    k_last = math.ceil(math.log(SETTLE_TOL / A) / math.log(r)) - 2
    m = joint_metrics(res, t_end=t_end)[0]
    assert m.settle_time == pytest.approx((k_last + 1) * DT - t_end, abs=1e-12)
    assert m.final_error == pytest.approx(-A * r ** (steps + 1), rel=1e-9)
    assert m.max_error == pytest.approx(A * r, rel=1e-12)  # at the start


def test_metrics_from_a_simulate_run() -> None:
    """joint_metrics reads the run's statistics: a coast from rest never moves (e = q0)."""
    arm = wheel(0.5)
    res = simulate(arm, hold(np.zeros(1)), np.array([0.02]), 1.0,
                   SimConfig(np.zeros(1), np.zeros(1), DT))  # fmt: skip
    m = joint_metrics(res, t_end=0.4)[0]
    assert m.rms_error == pytest.approx(0.02) and m.max_error == pytest.approx(0.02)
    assert m.final_error == pytest.approx(0.02) and m.settle_time is None  # 0.02 > 0.01
    assert m.saturated_pct == 0.0 and m.limit_contacts == 0
    cfg = SimConfig(np.zeros(1), np.zeros(1), DT)
    settled = joint_metrics(simulate(arm, hold(np.zeros(1)), np.array([0.005]), 1.0, cfg), 0.4)[0]
    assert settled.settle_time == 0.0  # inside the band from the start


def test_sample_steps_at_the_publisher_rate() -> None:
    # 2.5 s at 1 ms, 10 Hz: every 100th step, both ends included
    np.testing.assert_array_equal(sample_steps(2500, DT, 10.0), np.arange(26) * 100)
    # 3 Hz: periods of 333.33 steps, rounded to the nearest step
    np.testing.assert_array_equal(sample_steps(1000, DT, 3.0), [0, 333, 667, 1000])


def test_states_file_of_a_run_kept_at_the_output_rate() -> None:
    """The rows equal those of the same run kept at every step."""
    arm = wheel(0.5)
    ref = Reference(np.array([0.0, 1.0]), np.zeros((1, 6, 1)), np.array([0.3]))
    ref.coeffs[0, 1, 0] = 0.3  # q_ref = 0.3 t over the first second
    cfg = SimConfig(np.array([5.0]), np.array([1.0]), DT)
    full = simulate(arm, ref, np.zeros(1), 2.5, cfg)
    kept = simulate(arm, ref, np.zeros(1), 2.5, cfg, record=sample_steps(2500, DT, 10.0))
    assert len(kept.t) == 26 and len(full.t) == 2501
    a, b = sample_states(full, 10.0), sample_states(kept, 10.0)
    for col in a:
        np.testing.assert_array_equal(a[col], b[col])
    np.testing.assert_allclose(a["time"], np.arange(26) * 0.1, atol=1e-12)
    # the reference column is the polynomial: 0.3 t until 1 s, then held
    np.testing.assert_allclose(a["wheel.reference"], np.minimum(0.3 * a["time"], 0.3), atol=1e-15)
    text = states_bytes(a, "csv").decode()
    assert text.splitlines()[0] == "time,wheel.position,wheel.velocity,wheel.effort,wheel.reference"
    assert len(text.splitlines()) == 27
