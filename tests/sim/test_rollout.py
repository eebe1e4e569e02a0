"""The engine's joints and motors: unaligned joint axes (revolute and prismatic) run into
their stops, and the effort limit holds for the torque actually applied over a whole step.

(Both once failed: the compiled engine aborted on unaligned axes; the implicit Kd pushed
the applied torque past the limit. RK4 at joint stops is in test_integrators.py.)
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from armcli.robot.model import Robot
from armcli.sim import rollout as ro
from armcli.sim.options import Integrator
from armcli.sim.simulate import SimConfig, plant_of, simulated
from tests.sim.engines import run_held

ID_TOL = 1e-9  # [N·m] inverse dynamics vs reported torque: round-off of (v' - v) / dt
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


def _arm(model: pin.Model, lower: float = -1e3, upper: float = 1e3, **kw: float) -> Robot:
    n = model.nv
    base = dict(lower=lower, upper=upper, effort=np.inf, velocity=100.0, damping=0.0, friction=0.0)
    base.update(kw)
    return Robot(model).with_limits(**{k: np.full(n, float(v)) for k, v in base.items()})


def _plant(arm: Robot, cfg: SimConfig) -> ro.Plant:
    return plant_of(arm, cfg, energy_max=1e9)


def pendulum(length: float = 0.5) -> pin.Model:
    """Rod pendulum about y, hanging at q = 0: gravity torque -m g l sin q."""
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "hinge")
    inertia = pin.Inertia(1.0, np.array([0.0, 0.0, -length]), np.diag([1e-4] * 3))
    model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
    return model


# unaligned axes --------------------------------------------------------------------------


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_tilted_axes_run_into_the_prismatic_stop(integrator: Integrator) -> None:
    arm = simulated(Robot(pin.buildModelFromXML(TILTED_URDF)))
    kinds = {arm.model.joints[j].shortname() for j in range(1, arm.model.njoints)}
    assert {"JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"} <= kinds
    cfg = SimConfig(np.full(3, 20.0), np.full(3, 0.5), dt=5e-4, integrator=integrator)
    a = run_held(_plant(arm, cfg), np.zeros(3), np.zeros(3), 1000, [0.8, 0.04, -0.5])
    assert a.fail_step == -1 and a.trace.stop[:, 1].any()  # the prismatic stop at 0.05 m
    assert np.all(a.trace.q[:, 1] <= 0.05)


# effort saturation of the whole step -----------------------------------------------------


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
