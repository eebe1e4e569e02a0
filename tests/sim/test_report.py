"""Tracking metrics and joint-state sampling on synthetic runs with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.sim.report import joint_metrics
from armcli.sim.simulate import SimResult
from armcli.sim.states import sample_states, states_bytes

DT = 1e-3


def synthetic(
    err: np.ndarray, sat: np.ndarray | None = None, stop: np.ndarray | None = None
) -> SimResult:
    steps = err.shape[0] - 1
    t = np.arange(steps + 1) * DT
    q_ref = np.zeros((steps + 1, 1))
    return SimResult(
        joint_names=("j",),
        t=t,
        q=q_ref + err[:, None],
        v=np.gradient(err, DT)[:, None],
        q_ref=q_ref,
        v_ref=np.zeros_like(q_ref),
        tau=np.arange(steps, dtype=float)[:, None],
        saturated=(sat if sat is not None else np.zeros(steps, dtype=bool))[:, None],
        stop_active=(stop if stop is not None else np.zeros(steps, dtype=bool))[:, None],
        dt=DT,
        integrator="euler",
        backend="python",
        wall_time=0.0,
    )


def test_rms_and_max_of_a_sine() -> None:
    t = np.arange(4001) * DT
    amp = 0.02
    m = joint_metrics(synthetic(amp * np.sin(2 * math.pi * t)), t_end=0.0)[0]
    # whole periods of A sin: RMS = A / sqrt(2), max = A (sampled at the crest)
    assert m.rms_error == pytest.approx(amp / math.sqrt(2), rel=1e-3)
    assert m.max_error == pytest.approx(amp, rel=1e-6)
    # settled = inside 0.01 from then on: |A sin(2 pi t)| last exceeds A/2 at t = 4 - 1/12
    assert m.settle_time == pytest.approx(4.0 - 1.0 / 12.0, abs=2 * DT)


def test_settle_time_of_an_exponential() -> None:
    t = np.arange(5001) * DT
    e0, tau, t_end = 0.1, 0.5, 1.0
    err = np.where(t < t_end, e0, e0 * np.exp(-(t - t_end) / tau))
    m = joint_metrics(synthetic(err), t_end=t_end, tol=0.01)[0]
    # e0 exp(-s / tau) = tol  ->  s = tau ln(e0 / tol)
    assert m.settle_time == pytest.approx(tau * math.log(e0 / 0.01), abs=2 * DT)
    assert m.final_error == pytest.approx(e0 * math.exp(-4.0 / tau))
    m_strict = joint_metrics(synthetic(err), t_end=t_end, tol=1e-6)[0]
    assert m_strict.settle_time is None  # e(5 s) = 3.4e-5 is still outside 1e-6


def test_saturation_share_and_stop_contacts() -> None:
    steps = 1000
    sat = np.zeros(steps, dtype=bool)
    sat[100:350] = True  # 250 of 1000 steps
    stop = np.zeros(steps, dtype=bool)
    stop[[10, 11, 12, 500, 900, 901]] = True  # three separate contacts
    m = joint_metrics(synthetic(np.zeros(steps + 1), sat, stop), t_end=0.0)[0]
    assert m.saturated_pct == pytest.approx(25.0)
    assert m.limit_contacts == 3


def test_sampling_at_the_publisher_rate() -> None:
    res = synthetic(np.zeros(2501))  # 2.5 s at 1 ms
    cols = sample_states(res, rate=10.0)
    np.testing.assert_allclose(cols["time"], np.arange(26) * 0.1, atol=1e-12)  # 0 .. 2.5 s
    # effort sampled at step k is the torque applied during step k (here tau[k] = k)
    np.testing.assert_allclose(cols["j.effort"][:-1], np.arange(25) * 100)
    text = states_bytes(cols, "csv").decode()
    assert text.splitlines()[0] == "time,j.position,j.velocity,j.effort,j.reference"
    assert len(text.splitlines()) == 27
