"""The simulator against closed forms, conservation laws and a high-accuracy ODE solution."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from armcli.errors import InputError, SimulationError, UnstableLoopError
from armcli.robot.model import Robot
from armcli.sim import rollout as ro
from armcli.sim.options import Integrator
from armcli.sim.simulate import (
    SimConfig,
    check_limits,
    check_stability,
    plant_of,
    simulate,
    simulated,
)
from armcli.trajectory.message import loads_trajectory
from armcli.trajectory.reference import build_reference
from tests.helpers import load_robot
from tests.sim.engines import run_held

G = 9.81
WIDE = 1e3  # [rad] limits far away: no stop contact
ROUNDOFF = 1e-12


def pendulum(mass: float = 1.0, length: float = 0.5, gravity: bool = True) -> Robot:
    """Point-mass-like rod pendulum about y: I_pivot = m l^2 + I_c."""
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "hinge")
    I_c = np.diag([1e-4, 1e-4, 1e-4])
    model.appendBodyToJoint(
        jid, pin.Inertia(mass, np.array([0.0, 0.0, -length]), I_c), pin.SE3.Identity()
    )
    if not gravity:
        model.gravity.linear = np.zeros(3)
    return _arm(model)


def _arm(model: pin.Model, lower: float = -WIDE, upper: float = WIDE, **kw: float) -> Robot:
    n = model.nv
    base = dict(lower=lower, upper=upper, effort=np.inf, velocity=100.0, damping=0.0, friction=0.0)
    base.update(kw)
    return Robot(model).with_limits(**{k: np.full(n, float(v)) for k, v in base.items()})


@pytest.fixture(scope="module")
def arm(built_dir: Path) -> Robot:
    return simulated(load_robot(built_dir / "standalone_arm.urdf"))


def _plant(arm: Robot, cfg: SimConfig) -> ro.Plant:
    return plant_of(arm, cfg)


def _energy(model: pin.Model, q: np.ndarray, v: np.ndarray) -> float:
    data = model.createData()
    return pin.computeKineticEnergy(model, data, q, v) + pin.computePotentialEnergy(model, data, q)


def test_free_motion_keeps_velocity() -> None:
    arm = pendulum(gravity=False)
    cfg = SimConfig(kp=np.zeros(1), kd=np.zeros(1), dt=1e-3)
    r = run_held(_plant(arm, cfg), [0.2], [1.5], 2000).trace
    # Newton: no torque, no gravity -> v constant, q = q0 + v0 t
    np.testing.assert_allclose(r.v[:, 0], 1.5, atol=ROUNDOFF)
    np.testing.assert_allclose(r.q[:, 0], 0.2 + 1.5 * np.arange(2001) * 1e-3, atol=1e-9)


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_pendulum_small_amplitude_period(integrator: Integrator) -> None:
    m, length = 1.0, 0.5
    arm = pendulum(m, length)
    cfg = SimConfig(kp=np.zeros(1), kd=np.zeros(1), dt=1e-3, integrator=integrator)
    steps = 10_000
    r = run_held(_plant(arm, cfg), [0.01], [0.0], steps).trace
    q, t = r.q[:, 0], np.arange(steps + 1) * 1e-3
    up = np.nonzero((q[:-1] < 0) & (q[1:] >= 0))[0]
    crossings = t[up] - q[up] * 1e-3 / (q[up + 1] - q[up])  # linear interpolation
    period = np.mean(np.diff(crossings))
    # closed form T = 2 pi sqrt(I_pivot / (m g l)), I_pivot = m l^2 + I_yy
    expected = 2 * math.pi * math.sqrt((m * length**2 + 1e-4) / (m * G * length))
    # amplitude correction (1 + theta0^2/16) ~ 6e-6; Euler's phase error O(dt^2 w^2) ~ 1e-5
    assert period == pytest.approx(expected, rel=5e-5)


def test_energy_conserved_without_damping(arm: Robot) -> None:
    free = _arm(arm.model)
    cfg = SimConfig(kp=np.zeros(2), kd=np.zeros(2), dt=2.5e-4, integrator="rk4")
    steps = 40_000  # 10 s
    r = run_held(_plant(free, cfg), [0.4, -0.3], [0.0, 0.0], steps).trace
    e0 = _energy(free.model, r.q[0], r.v[0])
    energies = [_energy(free.model, r.q[k], r.v[k]) for k in range(0, steps + 1, 1000)]
    # conservative double pendulum (chaotic, up to ~55 rad/s): total energy constant;
    # RK4's O(dt^4) error at 0.25 ms is ~2e-9 J of ~1.8 J
    assert max(abs(e - e0) for e in energies) < 1e-7


def test_semi_implicit_euler_energy_bounded(arm: Robot) -> None:
    free = _arm(arm.model)
    energy_err = {}
    for dt in (1e-3, 1e-4):
        steps = round(10.0 / dt)
        cfg = SimConfig(kp=np.zeros(2), kd=np.zeros(2), dt=dt)
        # swinging about the hanging equilibrium for 10 s
        r = run_held(_plant(free, cfg), [math.pi - 0.3, 0.2], [0.0, 0.0], steps).trace
        e = np.array(
            [_energy(free.model, r.q[k], r.v[k]) for k in range(0, steps + 1, steps // 200)]
        )
        energy_err[dt] = np.max(np.abs(e - e[0]))
    # no damping: energy stays within O(dt) of its start (M(q) makes the scheme only
    # first-order accurate in energy, not exactly symplectic), and shrinks with dt
    assert energy_err[1e-3] < 1e-3  # [J], vs ~0.08 J of pendulum energy swing
    assert 5 < energy_err[1e-3] / energy_err[1e-4] < 20


def test_pd_with_gravity_compensation_converges(arm: Robot) -> None:
    plant_arm = _arm(arm.model, lower=0.0, upper=math.pi / 2, damping=0.1)
    cfg = SimConfig(kp=np.full(2, 50.0), kd=np.full(2, 5.0), dt=1e-3, gravity_comp=True)
    r = run_held(_plant(plant_arm, cfg), [0.2, 0.2], [0.0, 0.0], 8000, [0.7, 0.9]).trace
    # with g(q) cancelled the error dynamics are a damped linear system -> exact setpoint
    np.testing.assert_allclose(r.q[-1], [0.7, 0.9], atol=1e-6)
    np.testing.assert_allclose(r.v[-1], 0.0, atol=1e-5)


def test_coulomb_friction_holds_small_torque_without_chatter() -> None:
    arm = _arm(pendulum(gravity=False).model, friction=0.05)
    cfg = SimConfig(kp=np.array([1.0]), kd=np.zeros(1), dt=1e-3)
    # spring torque 1 * 0.03 < 0.05 N·m of friction
    r = run_held(_plant(arm, cfg), [0.0], [0.0], 3000, [0.03]).trace
    assert np.all(r.v == 0.0) and np.all(r.q == 0.0)  # exactly at rest: no creep, no chatter


def test_coulomb_friction_slip_acceleration() -> None:
    arm = _arm(pendulum(gravity=False).model, friction=0.05)
    I_pivot = 0.25 + 1e-4
    cfg = SimConfig(kp=np.array([1.0]), kd=np.zeros(1), dt=1e-4)
    r = run_held(_plant(arm, cfg), [0.0], [0.0], 100, [0.2]).trace
    # tau = 1 * 0.2 = 0.2 > 0.05: a = (tau - F)/I while q barely moves (10 ms)
    a = r.v[-1, 0] / 0.01
    assert a == pytest.approx((0.2 - 0.05) / I_pivot, rel=1e-3)


def test_hard_stop_no_pass_through_no_energy_gain(arm: Robot) -> None:
    stops = _arm(arm.model, lower=0.0, upper=math.pi / 2)
    cfg = SimConfig(kp=np.zeros(2), kd=np.zeros(2), dt=1e-3)
    r = run_held(_plant(stops, cfg), [0.3, 0.2], [2.0, 3.0], 3000).trace
    assert np.all(r.q >= 0.0) and np.all(r.q <= math.pi / 2)  # never beyond a stop
    assert r.stop.any()  # the stops were hit
    e = np.array([_energy(stops.model, r.q[k], r.v[k]) for k in range(3001)])
    # no damping: energy may only drop at impacts (symplectic O(dt) wiggle allowed)
    assert np.max(e) <= e[0] + 0.01


@pytest.mark.parametrize("dt", [1e-3, 5e-3, 1e-2])
def test_implicit_damping_stable_for_large_kd(arm: Robot, dt: float) -> None:
    # explicit Euler would need dt (Kd + D) lambda_max(M^-1) < 2, i.e. Kd < ~3.5 at 1 ms
    cfg = SimConfig(kp=np.full(2, 50.0), kd=np.full(2, 50.0), dt=dt, gravity_comp=True)
    check_stability(arm, cfg, np.zeros((1, 2)))
    tr = loads_trajectory("joint_names: [arm_base_forearm_joint]\npoints: [{positions: [0.8]}]",
                          dict.fromkeys(arm.names, (0.0, 2.0)))  # fmt: skip
    res = simulate(arm, build_reference(tr, arm.names, np.zeros(2)), np.zeros(2), 8.0, cfg)
    assert abs(res.q[-1, 0] - 0.8) < 0.01  # friction 0.05 / Kp 50 = 1e-3 rad band


def test_stability_check_refuses_and_explains(arm: Robot) -> None:
    cfg = SimConfig(kp=np.full(2, 50.0), kd=np.full(2, 5.0), dt=1e-3, integrator="rk4")
    with pytest.raises(UnstableLoopError, match=r"stable for dt <= .*default euler integrator"):
        check_stability(arm, cfg, np.zeros((1, 2)))
    stiff = SimConfig(kp=np.full(2, 1e8), kd=np.full(2, 5.0), dt=1e-3)
    with pytest.raises(UnstableLoopError, match=r"Kp up to 1e[+]08.* too stiff") as exc:
        check_stability(arm, stiff, np.zeros((1, 2)))
    assert exc.value.field is None  # the library names no option; the command does
    assert "--dt" not in str(exc.value)


def test_divergence_is_reported_not_nan(arm: Robot) -> None:
    unlimited = _arm(arm.model)  # no effort limit, no stops: nothing bounds the blow-up
    cfg = SimConfig(kp=np.full(2, 1e8), kd=np.zeros(2), dt=1e-3)
    tr = loads_trajectory("joint_names: [forearm_hand_joint]\npoints: [{positions: [0.5]}]",
                          dict.fromkeys(arm.names, (0.0, 2.0)))  # fmt: skip
    with pytest.raises(SimulationError) as exc:
        simulate(unlimited, build_reference(tr, arm.names, np.zeros(2)), np.zeros(2), 2.0, cfg)
    err = exc.value
    assert err.step is not None and err.step > 0 and err.time == pytest.approx(err.step * 1e-3)
    assert err.cause and "nan" not in str(err).lower()


def test_reported_effort_balances_gravity_at_rest(arm: Robot) -> None:
    no_friction = _arm(arm.model, lower=0.0, upper=math.pi / 2, damping=0.1)
    cfg = SimConfig(kp=np.full(2, 50.0), kd=np.full(2, 5.0), dt=1e-3)  # no gravity comp
    r = run_held(_plant(no_friction, cfg), [0.7, 0.9], [0.0, 0.0], 10_000, [0.7, 0.9]).trace
    q_end = r.q[-1]
    g = pin.computeGeneralizedGravity(arm.model, arm.model.createData(), q_end)
    # static equilibrium: the motor torque (the `effort` output) holds the arm against g(q)
    np.testing.assert_allclose(r.tau[-1], g, atol=1e-6)
    np.testing.assert_allclose(50.0 * ([0.7, 0.9] - q_end), g, atol=1e-6)  # the P term alone


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("friction", math.nan, "friction nan"),  # would freeze the joint
        ("friction", -0.1, "friction -0.1"),
        ("damping", math.inf, "damping inf"),
        ("lower", math.nan, "lower nan"),  # would mean "no stop"
        ("upper", math.nan, "upper nan"),
        # an effort <= 0 is no limit (inf), as the URDF reads: tests/robot/test_model.py
        ("velocity", math.nan, "velocity nan"),
    ],
)
def test_arm_refuses_values_that_are_not_numbers_or_out_of_order(
    arm: Robot, field: str, value: float, message: str
) -> None:
    bad = getattr(arm, field).copy()
    bad[1] = value
    with pytest.raises(InputError, match=rf"joint 'forearm_hand_joint': {message} "):
        check_limits(arm.with_limits(**{field: bad}))


def test_arm_refuses_limits_out_of_order(arm: Robot) -> None:
    with pytest.raises(InputError, match=r"lower limit 1 is above upper 0\.5"):
        simulated(arm.with_limits(lower=np.array([0.0, 1.0]), upper=np.array([1.0, 0.5])))


@pytest.mark.parametrize(
    ("kp", "kd", "dt"), [(math.nan, 1.0, 1e-3), (1.0, -1.0, 1e-3), (1.0, 1.0, math.nan)]
)
def test_sim_config_refuses_bad_gains_and_step(kp: float, kd: float, dt: float) -> None:
    with pytest.raises(InputError, match="must be finite"):
        SimConfig(np.full(2, kp), np.full(2, kd), dt=dt)
