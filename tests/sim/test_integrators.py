"""The integrators against independent references.

RK4 against DOP853 (scipy, rtol 1e-12) on Pinocchio's equations at every step, with
trajectory knots on and off the time grid and reference velocity jumps; semi-implicit
Euler's energy behaviour on conservative swings (what its docs say it conserves).
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from armcli.robot.model import Robot
from armcli.sim.simulate import SimConfig, plant_of, simulate, simulated
from armcli.trajectory.message import loads_trajectory
from armcli.trajectory.reference import Reference, build_reference
from tests.helpers import load_robot
from tests.sim.engines import run_held
from tests.sim.test_simulate import _arm, pendulum

RK4_STEP_TOL = 1e-6  # [rad] RK4 at 1 ms vs DOP853, at every step (issue 24)
DOP_TOL = 1e-12  # DOP853 rtol and atol
KP, KD, DAMPING, DT = 50.0, 2.0, 0.1, 1e-3  # dt (Kd + D) lambda_max(M^-1) = 1.2: RK4-stable
POINTS = [(0.6, 0.4), (0.9, 1.2), (0.5, 0.8), (0.3, 0.3)]
ON_GRID = (0.5, 1.0, 1.5, 2.0)
EQUILIBRIUM_TOL = 1e-9  # [rad] converged static equilibrium vs brentq on the statics
OFF_GRID = (0.5003, 1.0007, 1.4996, 2.0001)  # [s] between steps of 1 ms


def trajectory(times: tuple[float, ...], kind: str, first_at_zero: bool = False) -> str:
    """Positions only (linear: v_ref jumps at every knot), with velocities (cubic) or also
    accelerations (quintic)."""
    lines = ["joint_names: [arm_base_forearm_joint, forearm_hand_joint]", "points:"]
    pts = list(zip(POINTS, times, strict=True))
    if first_at_zero:
        pts = [((0.4, 0.5), 0.0), *pts]
    for (a, b), t in pts:
        extra = ""
        if kind in ("cubic", "quintic"):
            extra += ", velocities: [0.3, -0.2]"
        if kind == "quintic":
            extra += ", accelerations: [0.5, 0.1]"
        lines.append(f" - {{positions: [{a}, {b}]{extra}, time_from_start: {t}}}")
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def arm(built_dir: Path) -> Robot:
    model = simulated(load_robot(built_dir / "standalone_arm.urdf")).model
    return _arm(model, damping=DAMPING)  # stops far away, no friction: the smooth dynamics


def dop853(
    arm: Robot, ref: Reference, q0: np.ndarray, t_end: float, kd: float = KD, dt: float = DT
) -> np.ndarray:
    """q at every step time from DOP853 on q'' = ABA(q, v, PD - D v), restarted at each
    knot on that segment's polynomial, so it never steps across a discontinuity."""
    model, data = arm.model, arm.model.createData()

    def f(t: float, y: np.ndarray, t0: float, c: np.ndarray | None) -> np.ndarray:
        if c is None:  # after the last knot: the final position, held
            qr, vr = ref.final, np.zeros(2)
        else:  # the segment's quintic in local time, by Horner
            tau = t - t0
            qr = ((((c[5] * tau + c[4]) * tau + c[3]) * tau + c[2]) * tau + c[1]) * tau + c[0]
            vr = (((5 * c[5] * tau + 4 * c[4]) * tau + 3 * c[3]) * tau + 2 * c[2]) * tau + c[1]
        tau_m = KP * (qr - y[:2]) + kd * (vr - y[2:]) - DAMPING * y[2:]
        return np.concatenate([y[2:], pin.aba(model, data, y[:2], y[2:], tau_m)])

    steps = round(t_end / dt)
    ts = np.arange(steps + 1) * dt
    cuts = [0.0, *[k for k in ref.knots[1:] if k < t_end], t_end]
    y = np.concatenate([q0, np.zeros(2)])
    out = np.full((steps + 1, 2), np.nan)
    for s, (t0, t1) in enumerate(itertools.pairwise(cuts)):
        c = ref.coeffs[s] if s < ref.coeffs.shape[0] else None
        inside = (ts >= t0) & (ts <= t1)
        sol = solve_ivp(f, (t0, t1), y, "DOP853", rtol=DOP_TOL, atol=DOP_TOL, dense_output=True,
                        args=(t0, c))  # fmt: skip
        out[inside] = sol.sol(ts[inside])[:2].T
        y = sol.y[:, -1]
    return out


@pytest.mark.parametrize(
    ("times", "kind", "first_at_zero"),
    [
        (ON_GRID, "linear", False),
        (OFF_GRID, "linear", False),
        (OFF_GRID, "cubic", False),
        (OFF_GRID, "quintic", False),
        (OFF_GRID, "linear", True),  # the reference starts away from the arm
    ],
)
def test_rk4_follows_dop853_at_every_step(
    arm: Robot, times: tuple[float, ...], kind: str, first_at_zero: bool
) -> None:
    """Before the fix: 5.6e-6 rad (knots on the grid, the step after a velocity jump) and
    5.1e-4 rad (knots off the grid)."""
    q0, t_end = np.array([0.2, 0.2]), 2.2
    tr = loads_trajectory(trajectory(times, kind, first_at_zero),
                          dict.fromkeys(arm.names, (0.0, math.pi / 2)))  # fmt: skip
    ref = build_reference(tr, arm.names, q0)
    cfg = SimConfig(np.full(2, KP), np.full(2, KD), dt=DT, integrator="rk4")
    res = simulate(arm, ref, q0, t_end, cfg)
    err = np.max(np.abs(res.q - dop853(arm, ref, q0, t_end)), axis=1)
    assert err.max() < RK4_STEP_TOL, f"{err.max():.2e} rad at t = {res.t[np.argmax(err)]:.4f} s"


def _energy(model: pin.Model, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    data = model.createData()
    return np.array([
        pin.computeKineticEnergy(model, data, a, b) + pin.computePotentialEnergy(model, data, a)
        for a, b in zip(q, v, strict=True)
    ])  # fmt: skip


def _drift(arm: Robot, q0: list[float], dt: float, seconds: float) -> tuple[float, float]:
    """(energy drift [J/h] fitted over the run, largest |E - E0| [J]) of a free swing."""
    n = len(q0)
    steps = round(seconds / dt)
    r = run_held(plant_of(arm, SimConfig(np.zeros(n), np.zeros(n), dt=dt)), q0, np.zeros(n),
                 steps).trace  # fmt: skip
    every = slice(0, steps + 1, steps // 2000)
    e = _energy(arm.model, r.q[every], r.v[every])
    slope = np.polyfit(r.step[every] * dt, e, 1)[0]
    return float(slope * 3600.0), float(np.max(np.abs(e - e[0])))


def test_euler_is_symplectic_for_a_constant_mass_matrix() -> None:
    """One joint: M constant, and semi-implicit Euler is symplectic Euler. Its energy error
    stays bounded (an O(dt) wobble of the modified Hamiltonian) with no drift."""
    wobble_1, wobble_2 = (_drift(pendulum(), [2.5], 1e-3, s)[1] for s in (60.0, 600.0))
    drift, _ = _drift(pendulum(), [2.5], 1e-3, 600.0)
    # the same wobble over 60 s and 600 s (measured 8.3e-3 J), no trend (measured ~1e-5 J/h)
    assert wobble_2 < 1.05 * wobble_1
    assert abs(drift) < 1e-3


def test_euler_energy_drift_on_the_arm(arm: Robot) -> None:
    """Two links: M(q) varies and the Coriolis forces are taken at the step's start, so
    the scheme is not symplectic and a conservative swing's energy drifts. Measured +5.6e-2
    J/h at 1 ms over an hour (sim/simulate.py's docstring); it shrinks with dt."""
    free = _arm(arm.model)
    q0 = [math.pi - 0.3, 0.2]  # hanging, 0.3 rad off
    drift_1ms, _ = _drift(free, q0, 1e-3, 600.0)
    drift_05ms, _ = _drift(free, q0, 5e-4, 600.0)
    assert 0.0 < drift_1ms < 0.1  # [J/h] gains energy, slowly
    assert 0.0 < drift_05ms < drift_1ms


@pytest.mark.slow  # ~8 s: DOP853 at rtol 1e-12 through 3 s of quintic segments
def test_euler_is_first_order_against_dop853(arm: Robot) -> None:
    """Quintic segments (a smooth reference): Euler's error is O(dt) and halves with dt."""
    q0, t_end, kd = np.array([0.1, 0.1]), 3.0, 5.0
    tr = loads_trajectory(trajectory((1.0, 1.5, 2.0, 2.5), "quintic"),
                          dict.fromkeys(arm.names, (0.0, math.pi / 2)))  # fmt: skip
    ref = build_reference(tr, arm.names, q0)
    exact = dop853(arm, ref, q0, t_end, kd=kd, dt=5e-4)
    errs = {}
    for dt in (1e-3, 5e-4):
        res = simulate(arm, ref, q0, t_end, SimConfig(np.full(2, KP), np.full(2, kd), dt=dt))
        every = round(dt / 5e-4)
        errs[dt] = np.max(np.abs(res.q - exact[::every]))
    assert errs[1e-3] < 2e-3  # [rad] measured 7.3e-4 (O(dt) with this loop's ~0.5 s time scale)
    assert 1.6 < errs[1e-3] / errs[5e-4] < 2.4


# RK4 at joint stops (it once gave a resting joint dt a / 2 of phantom velocity) ----------


def test_rk4_resting_on_a_stop_has_no_phantom_velocity() -> None:
    # hanging pendulum held at q = 0.3 by its lower stop: gravity presses it on the stop
    arm = _arm(pendulum().model, lower=0.3, upper=2.0)
    cfg = SimConfig(np.zeros(1), np.zeros(1), dt=5e-4, integrator="rk4")
    a = run_held(plant_of(arm, cfg, energy_max=1e9), [0.3], [0.0], 2000, [0.3]).trace
    assert np.all(a.q[:, 0] == 0.3)  # on the stop, exactly
    assert np.all(a.v[:, 0] == 0.0)  # and at rest: no dt a / 2 into the stop
    assert np.all(a.stop[:, 0])


def test_rk4_coupled_joint_settles_at_its_static_equilibrium(built_dir: Path) -> None:
    model = simulated(load_robot(built_dir / "standalone_arm.urdf")).model
    arm = _arm(model, lower=0.0, upper=math.pi / 2, damping=0.2)
    kp, q2_ref = 50.0, 0.8
    cfg = SimConfig(np.array([0.0, kp]), np.array([0.0, 2.0]), dt=5e-4, integrator="rk4")
    a = run_held(plant_of(arm, cfg, energy_max=1e9), [math.pi / 2, 0.5], [0.0, 0.0], 16_000,  # 8 s
                 [math.pi / 2, q2_ref]).trace  # fmt: skip
    # gravity presses joint 1 on its upper stop; joint 2's statics: Kp (q_ref - q2) = g2(q)
    data = model.createData()

    def residual(q2: float) -> float:
        g = pin.computeGeneralizedGravity(model, data, np.array([math.pi / 2, q2]))
        return float(kp * (q2_ref - q2) - g[1])

    q2_eq = brentq(residual, 0.0, math.pi / 2, xtol=1e-14)
    assert a.q[-1, 0] == math.pi / 2 and a.v[-1, 0] == 0.0
    assert a.q[-1, 1] == pytest.approx(q2_eq, abs=EQUILIBRIUM_TOL)
    assert abs(a.v[-1, 1]) < EQUILIBRIUM_TOL


# RK4 order on positions-only trajectories (reference velocity jumps) --------------------

POSITIONS_ONLY = (  # linear segments: the reference velocity jumps at every knot
    "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
    " - {positions: [0.6, 0.4], time_from_start: 0.5}\n"
    " - {positions: [0.9, 1.2], time_from_start: 1.0}\n"
    " - {positions: [0.5, 0.8], time_from_start: 1.5}\n"
)


def test_rk4_is_fourth_order_on_positions_only_trajectory(built_dir: Path) -> None:
    model = simulated(load_robot(built_dir / "standalone_arm.urdf")).model
    arm = _arm(model, damping=0.1)
    kp, kd, t_end = 50.0, 1.0, 2.0
    tr = loads_trajectory(POSITIONS_ONLY, dict.fromkeys(arm.names, (0.0, math.pi / 2)))
    q0 = np.array([0.2, 0.2])
    ref = build_reference(tr, arm.names, q0)
    data = model.createData()

    def f(t: float, y: np.ndarray, seg: float) -> np.ndarray:
        qr, vr = (x[0] for x in ref.sample(np.array([t]), segment_time=np.array([seg])))
        tau = kp * (qr - y[:2]) + kd * (vr - y[2:]) - 0.1 * y[2:]
        return np.concatenate([y[2:], pin.aba(model, data, y[:2], y[2:], tau)])

    # DOP853 restarted at each knot, so it never steps across a reference discontinuity
    y = np.concatenate([q0, np.zeros(2)])
    knots = [0.0, 0.5, 1.0, 1.5, t_end]
    for t0, t1 in itertools.pairwise(knots):
        sol = solve_ivp(f, (t0, t1), y, "DOP853", rtol=1e-13, atol=1e-13, args=(0.5 * (t0 + t1),))
        y = sol.y[:, -1]
    errors = []
    for dt in (2e-3, 1e-3, 5e-4):
        cfg = SimConfig(np.full(2, kp), np.full(2, kd), dt=dt, integrator="rk4")
        errors.append(np.max(np.abs(simulate(arm, ref, q0, t_end, cfg).q[-1] - y[:2])))
    # fourth order: halving dt divides the error by 2^4 = 16 (measured 19 and 18)
    assert errors[0] < 1e-9
    assert 12 < errors[0] / errors[1] < 24 and 12 < errors[1] / errors[2] < 24
