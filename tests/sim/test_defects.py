"""Regression tests for the simulator defects of issue 11.

Each test failed before its fix: unaligned joint axes (the compiled engine aborted),
effort saturation of the whole-step motor torque, RK4 at joint stops and RK4's order on
positions-only trajectories.
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

from armcli.robot.load import load_model
from armcli.sim import rollout as ro
from armcli.sim.reference import build_reference
from armcli.sim.simulate import Arm, SimConfig, arm_from_model, plant_of, simulate
from armcli.sim.trajectory import loads_trajectory
from tests.sim.engines import run_held

ID_TOL = 1e-9  # [N·m] inverse dynamics vs reported torque: round-off of (v' - v) / dt
EQUILIBRIUM_TOL = 1e-9  # [rad] converged static equilibrium vs brentq on the statics
TILTED_URDF = """<robot name="tilted">
  <link name="base"/>
  <link name="a"><inertial><mass value="1.2"/><origin xyz="0.1 0.02 -0.2"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0.002" izz="0.01"/></inertial></link>
  <link name="b"><inertial><mass value="0.7"/><origin xyz="0 0.1 -0.1"/>
    <inertia ixx="0.01" ixy="0" ixz="0.001" iyy="0.01" iyz="0" izz="0.005"/></inertial></link>
  <link name="c"><inertial><mass value="0.4"/><origin xyz="0.05 0 -0.05"/>
    <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.003"/></inertial></link>
  <joint name="tilted_revolute" type="revolute"><parent link="base"/><child link="a"/>
    <axis xyz="0.3 0.5 0.8"/><limit lower="-2" upper="2" effort="50" velocity="5"/></joint>
  <joint name="tilted_prismatic" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 -0.3" rpy="0.2 0 0.1"/><axis xyz="0 0.6 -0.8"/>
    <limit lower="-0.05" upper="0.05" effort="40" velocity="1"/></joint>
  <joint name="y_revolute" type="revolute"><parent link="b"/><child link="c"/>
    <origin xyz="0 0.1 -0.2"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="20" velocity="5"/></joint>
</robot>"""


def _arm(model: pin.Model, lower: float = -1e3, upper: float = 1e3, **kw: float) -> Arm:
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


def _plant(arm: Arm, cfg: SimConfig) -> ro.Plant:
    return plant_of(arm, cfg, energy_max=1e9)


def pendulum(length: float = 0.5) -> pin.Model:
    """Rod pendulum about y, hanging at q = 0: gravity torque -m g l sin q."""
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "hinge")
    inertia = pin.Inertia(1.0, np.array([0.0, 0.0, -length]), np.diag([1e-4] * 3))
    model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
    return model


# (a) unaligned axes ---------------------------------------------------------------------


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_tilted_axes_run_into_the_prismatic_stop(integrator: str) -> None:
    arm = arm_from_model(pin.buildModelFromXML(TILTED_URDF))
    kinds = {arm.model.joints[j].shortname() for j in range(1, arm.model.njoints)}
    assert {"JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"} <= kinds
    cfg = SimConfig(np.full(3, 20.0), np.full(3, 0.5), dt=5e-4, integrator=integrator)
    a = run_held(_plant(arm, cfg), np.zeros(3), np.zeros(3), 1000, [0.8, 0.04, -0.5])
    assert a.fail_step == -1 and a.trace.stop[:, 1].any()  # the prismatic stop at 0.05 m
    assert np.all(a.trace.q[:, 1] <= 0.05)


# (b) effort saturation of the whole step ------------------------------------------------


@pytest.mark.parametrize("kd", [5.0, 50.0])
def test_effort_limit_holds_for_the_applied_torque(kd: float) -> None:
    """A weak motor (4 N·m) against gravity (up to 4.9 N·m): the implicit Kd must not
    push the applied torque past the limit, and the reported torque is the applied one."""
    effort, dt = 4.0, 1e-3  # before the fix: 1.0035x (Kd 5), 1.031x (Kd 50) the limit
    arm = _arm(pendulum(), effort=effort, damping=0.05)
    cfg = SimConfig(np.array([50.0]), np.array([kd]), dt=dt)
    a = run_held(_plant(arm, cfg), [math.pi / 2], [0.0], 2000, [math.pi / 2]).trace
    assert np.max(np.abs(a.tau)) <= effort * (1 + 1e-15)
    at_limit = np.abs(a.tau[:, 0]) == effort
    assert at_limit.any() and (a.saturated[:, 0] == at_limit).all()
    # inverse dynamics (RNEA) of each step: M (v' - v)/dt + C v + g + D v' is the torque
    # the joint received; Euler's ABA solves exactly that, so it must equal the report
    data = arm.model.createData()
    for k in range(0, 2000, 7):
        acc = (a.v[k + 1] - a.v[k]) / dt
        applied = pin.rnea(arm.model, data, a.q[k], a.v[k], acc) + 0.05 * a.v[k + 1]
        assert applied[0] == pytest.approx(a.tau[k, 0], abs=ID_TOL)


# (c) RK4 at joint stops -----------------------------------------------------------------


def test_rk4_resting_on_a_stop_has_no_phantom_velocity() -> None:
    # hanging pendulum held at q = 0.3 by its lower stop: gravity presses it on the stop
    arm = _arm(pendulum(), lower=0.3, upper=2.0)
    cfg = SimConfig(np.zeros(1), np.zeros(1), dt=5e-4, integrator="rk4")
    a = run_held(_plant(arm, cfg), [0.3], [0.0], 2000, [0.3]).trace
    assert np.all(a.q[:, 0] == 0.3)  # on the stop, exactly
    assert np.all(a.v[:, 0] == 0.0)  # and at rest: no dt a / 2 into the stop
    assert np.all(a.stop[:, 0])


def test_rk4_coupled_joint_settles_at_its_static_equilibrium(built_dir: Path) -> None:
    model = arm_from_model(load_model(built_dir / "standalone_arm.urdf").model).model
    arm = _arm(model, lower=0.0, upper=math.pi / 2, damping=0.2)
    kp, q2_ref = 50.0, 0.8
    cfg = SimConfig(np.array([0.0, kp]), np.array([0.0, 2.0]), dt=5e-4, integrator="rk4")
    a = run_held(_plant(arm, cfg), [math.pi / 2, 0.5], [0.0, 0.0], 16_000,  # 8 s
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


# (d) RK4 order on positions-only trajectories -------------------------------------------

POSITIONS_ONLY = (  # linear segments: the reference velocity jumps at every knot
    "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
    " - {positions: [0.6, 0.4], time_from_start: 0.5}\n"
    " - {positions: [0.9, 1.2], time_from_start: 1.0}\n"
    " - {positions: [0.5, 0.8], time_from_start: 1.5}\n"
)


def test_rk4_is_fourth_order_on_positions_only_trajectory(built_dir: Path) -> None:
    model = arm_from_model(load_model(built_dir / "standalone_arm.urdf").model).model
    arm = _arm(model, damping=0.1)
    kp, kd, t_end = 50.0, 1.0, 2.0
    tr = loads_trajectory(POSITIONS_ONLY, dict.fromkeys(arm.joint_names, (0.0, math.pi / 2)))
    q0 = np.array([0.2, 0.2])
    ref = build_reference(tr, arm.joint_names, q0)
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
