"""The simulator against closed forms, conservation laws and a high-accuracy ODE solution."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import solve_ivp

from armcli.errors import InputError, SimulationError
from armcli.sim import native
from armcli.sim import rollout as ro
from armcli.sim.reference import build_reference
from armcli.sim.simulate import (
    Arm,
    SimConfig,
    arm_from_model,
    check_stability,
    params_of,
    simulate,
)
from armcli.sim.trajectory import loads_trajectory
from armcli.urdf.pinocchio import load_model
from tests.sim.engines import FAST, require_native  # FAST for long runs; equality is tested

G = 9.81
BACKENDS = ["python", "native"]
WIDE = 1e3  # [rad] limits far away: no stop contact
ROUNDOFF = 1e-12
ODE_TOL = 1e-6  # [rad] RK4 at dt = 0.5 ms vs DOP853 (the requirement)
SMOOTH = (  # quintic segments: reference position, velocity and acceleration continuous
    "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
    " - {positions: [0.5, 0.4], velocities: [0.3, 0.6], accelerations: [0, 0],\n"
    "    time_from_start: 1.0}\n"
    " - {positions: [0.9, 1.1], velocities: [0, 0], accelerations: [0, 0], time_from_start: 2}\n"
    " - {positions: [0.3, 0.7], velocities: [0, 0], accelerations: [0, 0], time_from_start: 3}\n"
)


def pendulum(mass: float = 1.0, length: float = 0.5, gravity: bool = True) -> Arm:
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


def _arm(model: pin.Model, lower: float = -WIDE, upper: float = WIDE, **kw: float) -> Arm:
    n = model.nv
    base = dict(effort=np.inf, velocity=100.0, damping=0.0, friction=0.0)
    base.update(kw)
    return Arm(
        model=model,
        joint_names=tuple(model.names[1:]),
        lower=np.full(n, lower),
        upper=np.full(n, upper),
        **{k: np.full(n, float(v)) for k, v in base.items()},
    )


@pytest.fixture(scope="module")
def arm(built_dir: Path) -> Arm:
    return arm_from_model(load_model(built_dir / "standalone_arm.urdf").model)


def _plant(arm: Arm, cfg: SimConfig, energy_max: float = np.inf) -> ro.Plant:
    return ro.Plant(
        arm.model, params_of(arm, cfg), cfg.gravity_comp, cfg.dt, cfg.integrator, energy_max
    )


def _run(backend: str, plant: ro.Plant, q0, v0, ref: np.ndarray) -> ro.Rollout:
    q0, v0 = np.asarray(q0, dtype=float), np.asarray(v0, dtype=float)
    if backend == "native":
        return native.rollout(require_native(), plant, q0, v0, ref)
    return ro.rollout_python(plant, q0, v0, ref)


def _const_ref(n: int, steps: int, q: float = 0.0, sub: int = 1) -> np.ndarray:
    ref = np.zeros((sub * steps + 1, 2 * n))
    ref[:, :n] = q
    return ref


def _energy(model: pin.Model, q: np.ndarray, v: np.ndarray) -> float:
    data = model.createData()
    return pin.computeKineticEnergy(model, data, q, v) + pin.computePotentialEnergy(model, data, q)


@pytest.mark.parametrize("backend", BACKENDS)
def test_free_motion_keeps_velocity(backend: str) -> None:
    arm = pendulum(gravity=False)
    cfg = SimConfig(kp=np.zeros(1), kd=np.zeros(1), dt=1e-3)
    r = _run(backend, _plant(arm, cfg), [0.2], [1.5], _const_ref(1, 2000))
    # Newton: no torque, no gravity -> v constant, q = q0 + v0 t
    np.testing.assert_allclose(r.v[:, 0], 1.5, atol=ROUNDOFF)
    np.testing.assert_allclose(r.q[:, 0], 0.2 + 1.5 * np.arange(2001) * 1e-3, atol=1e-9)


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_pendulum_small_amplitude_period(integrator: str) -> None:
    m, length = 1.0, 0.5
    arm = pendulum(m, length)
    cfg = SimConfig(kp=np.zeros(1), kd=np.zeros(1), dt=1e-3, integrator=integrator)
    steps = 10_000
    sub = ro.rows_per_step(integrator)
    r = _run(FAST, _plant(arm, cfg), [0.01], [0.0], _const_ref(1, steps, sub=sub))
    q, t = r.q[:, 0], np.arange(steps + 1) * 1e-3
    up = np.nonzero((q[:-1] < 0) & (q[1:] >= 0))[0]
    crossings = t[up] - q[up] * 1e-3 / (q[up + 1] - q[up])  # linear interpolation
    period = np.mean(np.diff(crossings))
    # closed form T = 2 pi sqrt(I_pivot / (m g l)), I_pivot = m l^2 + I_yy
    expected = 2 * math.pi * math.sqrt((m * length**2 + 1e-4) / (m * G * length))
    # amplitude correction (1 + theta0^2/16) ~ 6e-6; Euler's phase error O(dt^2 w^2) ~ 1e-5
    assert period == pytest.approx(expected, rel=5e-5)


def test_energy_conserved_without_damping(arm: Arm) -> None:
    free = _arm(arm.model)
    cfg = SimConfig(kp=np.zeros(2), kd=np.zeros(2), dt=2.5e-4, integrator="rk4")
    steps = 40_000  # 10 s
    r = _run(
        FAST, _plant(free, cfg), [0.4, -0.3], [0.0, 0.0], _const_ref(2, steps, sub=ro.RK4_ROWS)
    )
    e0 = _energy(free.model, r.q[0], r.v[0])
    energies = [_energy(free.model, r.q[k], r.v[k]) for k in range(0, steps + 1, 1000)]
    # conservative double pendulum (chaotic, up to ~55 rad/s): total energy constant;
    # RK4's O(dt^4) error at 0.25 ms is ~2e-9 J of ~1.8 J
    assert max(abs(e - e0) for e in energies) < 1e-7


def test_semi_implicit_euler_energy_bounded(arm: Arm) -> None:
    free = _arm(arm.model)
    energy_err = {}
    for dt in (1e-3, 1e-4):
        steps = round(10.0 / dt)
        cfg = SimConfig(kp=np.zeros(2), kd=np.zeros(2), dt=dt)
        # swinging about the hanging equilibrium for 10 s
        r = _run(FAST, _plant(free, cfg), [math.pi - 0.3, 0.2], [0.0, 0.0], _const_ref(2, steps))
        e = np.array(
            [_energy(free.model, r.q[k], r.v[k]) for k in range(0, steps + 1, steps // 200)]
        )
        energy_err[dt] = np.max(np.abs(e - e[0]))
    # no damping: energy stays within O(dt) of its start (M(q) makes the scheme only
    # first-order accurate in energy, not exactly symplectic), and shrinks with dt
    assert energy_err[1e-3] < 1e-3  # [J], vs ~0.08 J of pendulum energy swing
    assert 5 < energy_err[1e-3] / energy_err[1e-4] < 20


@pytest.mark.parametrize("backend", BACKENDS)
def test_pd_with_gravity_compensation_converges(arm: Arm, backend: str) -> None:
    plant_arm = _arm(arm.model, lower=0.0, upper=math.pi / 2, damping=0.1)
    cfg = SimConfig(kp=np.full(2, 50.0), kd=np.full(2, 5.0), dt=1e-3, gravity_comp=True)
    ref = _const_ref(2, 8000)
    ref[:, :2] = [0.7, 0.9]
    r = _run(backend, _plant(plant_arm, cfg), [0.2, 0.2], [0.0, 0.0], ref)
    # with g(q) cancelled the error dynamics are a damped linear system -> exact setpoint
    np.testing.assert_allclose(r.q[-1], [0.7, 0.9], atol=1e-6)
    np.testing.assert_allclose(r.v[-1], 0.0, atol=1e-5)


@pytest.mark.parametrize("backend", BACKENDS)
def test_coulomb_friction_holds_small_torque_without_chatter(backend: str) -> None:
    arm = _arm(pendulum(gravity=False).model, friction=0.05)
    cfg = SimConfig(kp=np.array([1.0]), kd=np.zeros(1), dt=1e-3)
    ref = _const_ref(1, 3000, q=0.03)  # spring torque 1 * 0.03 < 0.05 N·m of friction
    r = _run(backend, _plant(arm, cfg), [0.0], [0.0], ref)
    assert np.all(r.v == 0.0) and np.all(r.q == 0.0)  # exactly at rest: no creep, no chatter


@pytest.mark.parametrize("backend", BACKENDS)
def test_coulomb_friction_slip_acceleration(backend: str) -> None:
    arm = _arm(pendulum(gravity=False).model, friction=0.05)
    I_pivot = 0.25 + 1e-4
    cfg = SimConfig(kp=np.array([1.0]), kd=np.zeros(1), dt=1e-4)
    r = _run(backend, _plant(arm, cfg), [0.0], [0.0], _const_ref(1, 100, q=0.2))
    # tau = 1 * 0.2 = 0.2 > 0.05: a = (tau - F)/I while q barely moves (10 ms)
    a = r.v[-1, 0] / 0.01
    assert a == pytest.approx((0.2 - 0.05) / I_pivot, rel=1e-3)


@pytest.mark.parametrize("backend", BACKENDS)
def test_hard_stop_no_pass_through_no_energy_gain(arm: Arm, backend: str) -> None:
    stops = _arm(arm.model, lower=0.0, upper=math.pi / 2)
    cfg = SimConfig(kp=np.zeros(2), kd=np.zeros(2), dt=1e-3)
    r = _run(backend, _plant(stops, cfg), [0.3, 0.2], [2.0, 3.0], _const_ref(2, 3000))
    assert np.all(r.q >= 0.0) and np.all(r.q <= math.pi / 2)  # never beyond a stop
    assert r.flags[:, :].any()  # the stops were hit
    e = np.array([_energy(stops.model, r.q[k], r.v[k]) for k in range(3001)])
    # no damping: energy may only drop at impacts (symplectic O(dt) wiggle allowed)
    assert np.max(e) <= e[0] + 0.01


def _ode_reference(arm: Arm, cfg: SimConfig, ref, q0: np.ndarray, ts: np.ndarray) -> np.ndarray:
    """q at times `ts` from DOP853 on the same smooth dynamics (no friction, no stops)."""
    model, data = arm.model, arm.model.createData()

    def f(t: float, y: np.ndarray) -> np.ndarray:
        q, v = y[:2], y[2:]
        qr, vr = (x[0] for x in ref.sample(np.array([t])))
        tau = cfg.kp * (qr - q) + cfg.kd * (vr - v) - arm.damping * v
        return np.concatenate([v, pin.aba(model, data, q, v, tau)])

    sol = solve_ivp(f, (0, ts[-1]), np.concatenate([q0, np.zeros(2)]), method="DOP853",
                    rtol=1e-12, atol=1e-12, t_eval=ts, max_step=0.01)  # fmt: skip
    return sol.y[:2].T


def test_rk4_and_euler_against_dop853(arm: Arm) -> None:
    smooth_arm = _arm(arm.model, lower=-WIDE, upper=WIDE, damping=0.1)
    tr = loads_trajectory(SMOOTH, dict.fromkeys(arm.joint_names, (0.0, math.pi / 2)))
    q0 = np.array([0.1, 0.1])
    ref = build_reference(tr, arm.joint_names, q0)
    t_end = 3.5
    ts = np.arange(0, 36) * 0.1  # compare every 0.1 s over the whole run
    exact = _ode_reference(smooth_arm, SimConfig(np.full(2, 50.0), np.full(2, 5.0)), ref, q0, ts)
    errs = {}
    for integ, dt in (("rk4", 5e-4), ("euler", 1e-3), ("euler", 5e-4)):
        cfg = SimConfig(np.full(2, 50.0), np.full(2, 5.0), dt=dt, integrator=integ)
        res = simulate(smooth_arm, ref, q0, t_end, cfg)
        idx = np.round(ts / dt).astype(int)
        errs[integ, dt] = np.max(np.abs(res.q[idx] - exact))
    assert errs["rk4", 5e-4] < ODE_TOL
    # Euler is first order: its error is O(dt) and halves with dt
    assert errs["euler", 1e-3] < 50 * 1e-3 * 0.1
    assert 1.6 < errs["euler", 1e-3] / errs["euler", 5e-4] < 2.4


@pytest.mark.parametrize("dt", [1e-3, 5e-3, 1e-2])
def test_implicit_damping_stable_for_large_kd(arm: Arm, dt: float) -> None:
    # explicit Euler would need dt (Kd + D) lambda_max(M^-1) < 2, i.e. Kd < ~3.5 at 1 ms
    cfg = SimConfig(kp=np.full(2, 50.0), kd=np.full(2, 50.0), dt=dt, gravity_comp=True)
    check_stability(arm, cfg, np.zeros((1, 2)))
    tr = loads_trajectory("joint_names: [arm_base_forearm_joint]\npoints: [{positions: [0.8]}]",
                          dict.fromkeys(arm.joint_names, (0.0, 2.0)))  # fmt: skip
    res = simulate(arm, build_reference(tr, arm.joint_names, np.zeros(2)), np.zeros(2), 8.0, cfg)
    assert abs(res.q[-1, 0] - 0.8) < 0.01  # friction 0.05 / Kp 50 = 1e-3 rad band


def test_stability_check_refuses_and_explains(arm: Arm) -> None:
    cfg = SimConfig(kp=np.full(2, 50.0), kd=np.full(2, 5.0), dt=1e-3, integrator="rk4")
    with pytest.raises(InputError, match=r"`SimConfig.dt` <= .*euler"):
        check_stability(arm, cfg, np.zeros((1, 2)))
    stiff = SimConfig(kp=np.full(2, 1e8), kd=np.full(2, 5.0), dt=1e-3)
    with pytest.raises(InputError, match="Kp is too stiff"):
        check_stability(arm, stiff, np.zeros((1, 2)))


@pytest.mark.parametrize("backend", BACKENDS)
def test_divergence_is_reported_not_nan(arm: Arm, backend: str) -> None:
    unlimited = _arm(arm.model)  # no effort limit, no stops: nothing bounds the blow-up
    cfg = SimConfig(kp=np.full(2, 1e8), kd=np.zeros(2), dt=1e-3, backend=backend)
    tr = loads_trajectory("joint_names: [forearm_hand_joint]\npoints: [{positions: [0.5]}]",
                          dict.fromkeys(arm.joint_names, (0.0, 2.0)))  # fmt: skip
    with pytest.raises(SimulationError) as exc:
        simulate(
            unlimited, build_reference(tr, arm.joint_names, np.zeros(2)), np.zeros(2), 2.0, cfg
        )
    err = exc.value
    assert err.step is not None and err.step > 0 and err.time == pytest.approx(err.step * 1e-3)
    assert err.cause and "nan" not in str(err).lower()


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_native_matches_python(arm: Arm, integrator: str) -> None:
    require_native()
    text = (
        "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
        " - {positions: [1.5707963267948966, 0.4], time_from_start: 0.5}\n"
        " - {positions: [0.0, 1.5707963267948966], time_from_start: 1.0}\n"
    )
    tr = loads_trajectory(text, dict.fromkeys(arm.joint_names, (0.0, math.pi / 2)))
    ref = build_reference(tr, arm.joint_names, np.zeros(2))
    low_effort = Arm(**{**arm.__dict__, "effort": np.array([3.0, 1.0])})  # force saturation
    out = {}
    for be in ("python", "native"):
        cfg = SimConfig(np.full(2, 50.0), np.full(2, 2.0), dt=5e-4, integrator=integrator,
                        gravity_comp=True, backend=be)  # fmt: skip
        out[be] = simulate(low_effort, ref, np.zeros(2), 2.0, cfg)
    a, b = out["python"], out["native"]
    assert a.saturated.any() and a.stop_active.any()  # the hard paths are exercised
    np.testing.assert_allclose(a.q, b.q, atol=ROUNDOFF, rtol=0)
    np.testing.assert_allclose(a.v, b.v, atol=ROUNDOFF, rtol=0)
    np.testing.assert_allclose(a.tau, b.tau, atol=ROUNDOFF, rtol=0)


def test_reported_effort_balances_gravity_at_rest(arm: Arm) -> None:
    no_friction = _arm(arm.model, lower=0.0, upper=math.pi / 2, damping=0.1)
    cfg = SimConfig(kp=np.full(2, 50.0), kd=np.full(2, 5.0), dt=1e-3)  # no gravity comp
    ref = _const_ref(2, 10_000)
    ref[:, :2] = [0.7, 0.9]
    r = _run(FAST, _plant(no_friction, cfg), [0.7, 0.9], [0.0, 0.0], ref)
    q_end = r.q[-1]
    g = pin.computeGeneralizedGravity(arm.model, arm.model.createData(), q_end)
    # static equilibrium: the motor torque (the `effort` output) holds the arm against g(q)
    np.testing.assert_allclose(r.tau[-1], g, atol=1e-6)
    np.testing.assert_allclose(50.0 * ([0.7, 0.9] - q_end), g, atol=1e-6)  # the P term alone
