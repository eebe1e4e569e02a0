"""Continuous joints (URDF `continuous`, Pinocchio RUBX/Y/Z: nq = 2 as cos/sin, nv = 1).

The simulator's state holds the joint's angle, unbounded; there are no stops. Checked
against a closed-form pendulum energy, free rotation and a revolute twin with stops far
away, which must move identically.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from armcli.cli import main
from armcli.robot.model import Robot
from armcli.sim import rollout as ro
from armcli.sim.simulate import SimConfig, plant_of, simulated
from tests.helpers import DEFAULT_SPEC
from tests.sim.engines import run_held

M, L, I_C, G = 1.0, 0.5, 1e-4, 9.81  # [kg], [m], [kg·m²] about the centre of mass, [m/s²]
I_PIVOT = M * L**2 + I_C  # [kg·m²] parallel axis
TWIN_TOL = 1e-9  # [rad] continuous vs revolute twin: the same dynamics, cos/sin given vs computed
ENERGY_TOL = 1e-7  # [J] RK4 at 0.25 ms, O(dt^4) on ~3 J of swing energy
FREE_TOL = 1e-9  # [rad] free rotation vs q0 + v0 t: round-off of 4000 additions


def pendulum_urdf(joint: str, axis: str = "0 1 0", limits: str = "") -> str:
    """A rod pendulum (centre of mass L below the pivot) on a `joint` joint about `axis`."""
    return f"""<robot name="p">
  <link name="base"/>
  <link name="rod"><inertial><origin xyz="0 0 {-L}"/><mass value="{M}"/>
    <inertia ixx="{I_C}" ixy="0" ixz="0" iyy="{I_C}" iyz="0" izz="{I_C}"/></inertial></link>
  <joint name="hinge" type="{joint}"><parent link="base"/><child link="rod"/>
    <axis xyz="{axis}"/><limit effort="100" velocity="100" {limits}/></joint>
</robot>"""


def _arm(urdf: str) -> Robot:
    return simulated(Robot(pin.buildModelFromXML(urdf)))


def _plant(arm: Robot, integrator: str, dt: float) -> ro.Plant:
    cfg = SimConfig(kp=np.zeros(1), kd=np.zeros(1), dt=dt, integrator=integrator)  # type: ignore[arg-type]
    return plant_of(arm, cfg)


def test_continuous_joint_has_no_limits() -> None:
    arm = _arm(pendulum_urdf("continuous"))
    assert arm.model.nq == 2 and arm.model.nv == 1  # Pinocchio's (cos, sin) configuration
    assert arm.lower[0] == -math.inf and arm.upper[0] == math.inf


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_looping_pendulum_equals_its_revolute_twin(integrator: str) -> None:
    """Launched at 12 rad/s from hanging, it goes over the top again and again (needs
    v0 > sqrt(4 m g L / I) = 8.9 rad/s); the revolute twin's stops are 1000 rad away."""
    dt, steps = 1e-3, 3000
    cont = _arm(pendulum_urdf("continuous"))
    twin = _arm(pendulum_urdf("revolute", limits='lower="-1000" upper="1000"'))
    run_a = run_held(_plant(cont, integrator, dt), [0.0], [12.0], steps)
    a = run_a.trace
    b = run_held(_plant(twin, integrator, dt), [0.0], [12.0], steps).trace
    assert run_a.fail_step == -1 and not (a.stop.any() or a.saturated.any())
    assert a.q[-1, 0] > 4 * math.pi  # the reported angle is unbounded, not wrapped
    assert np.all(np.diff(a.q[:, 0]) > 0)  # it keeps turning the same way
    np.testing.assert_allclose(a.q, b.q, atol=TWIN_TOL, rtol=0)
    np.testing.assert_allclose(a.v, b.v, atol=TWIN_TOL * 100, rtol=0)


def test_energy_conserved_while_looping() -> None:
    dt, steps = 2.5e-4, 12_000
    arm = _arm(pendulum_urdf("continuous"))
    r = run_held(_plant(arm, "rk4", dt), [0.3], [10.0], steps).trace
    q, v = r.q[:, 0], r.v[:, 0]
    # closed form: E = I_pivot v² / 2 - m g L cos q (centre of mass at -L cos q)
    energy = 0.5 * I_PIVOT * v**2 - M * G * L * np.cos(q)
    assert q[-1] > 6 * math.pi
    assert np.max(np.abs(energy - energy[0])) < ENERGY_TOL


def test_free_rotation_about_the_vertical() -> None:
    """Axis along gravity: no torque, so q = q0 + v0 t exactly, far beyond 2 pi."""
    dt, steps = 1e-3, 4000
    arm = _arm(pendulum_urdf("continuous", axis="0 0 1"))
    r = run_held(_plant(arm, "euler", dt), [3.0], [5.0], steps).trace
    t = np.arange(steps + 1) * dt
    np.testing.assert_allclose(r.q[:, 0], 3.0 + 5.0 * t, atol=FREE_TOL, rtol=0)
    assert r.q[-1, 0] == pytest.approx(23.0)


RRBOT = """<robot name="rrbot">
  <link name="world"/>
  <link name="l1"><inertial><origin xyz="0 0 0.45"/><mass value="1"/>
    <inertia ixx="0.07" ixy="0" ixz="0" iyy="0.07" iyz="0" izz="0.001"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0 0 0.45"/><mass value="1"/>
    <inertia ixx="0.07" ixy="0" ixz="0" iyy="0.07" iyz="0" izz="0.001"/></inertial></link>
  <joint name="joint1" type="continuous"><parent link="world"/><child link="l1"/>
    <origin xyz="0 0 2"/><axis xyz="0 1 0"/><dynamics damping="0.7"/></joint>
  <joint name="joint2" type="continuous"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0.1 0.9"/><axis xyz="0 1 0"/><dynamics damping="0.7"/></joint>
</robot>"""


def test_simulate_cli_runs_continuous_joints(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """rrbot-like: two continuous joints, one turned past 2 pi; the states file has angles."""
    urdf, out = tmp_path / "rrbot.urdf", tmp_path / "states.csv"
    urdf.write_text(RRBOT, encoding="utf-8")
    msg = "{joint_names: [joint1, joint2], points: [{positions: [7.5, -0.5], time_from_start: 3}]}"
    args = ["simulate", "--urdf", str(urdf), "--message", msg, "--kp", "400", "--kd", "40",
            "--gravity-comp", "--duration", "6", "--output", str(out)]  # fmt: skip
    try:
        main(args)
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    err = capsys.readouterr().err
    assert code == 0, err
    with out.open() as fh:
        rows = list(csv.DictReader(fh))
    final = float(rows[-1]["joint1.position"])
    # tracked to the target angle 7.5 rad (> 2 pi), not wrapped to 7.5 - 2 pi = 1.22
    assert final == pytest.approx(7.5, abs=0.01)
    assert float(rows[-1]["joint1.reference"]) == 7.5


def test_spec_path_runs_a_continuous_joint(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The default spec with its hand joint made continuous, driven past 2 pi."""
    text = DEFAULT_SPEC.read_text(encoding="utf-8")
    head, tail = text.split("forearm_hand_joint:\n      type: revolute", 1)
    spec = tmp_path / "robot.yaml"
    spec.write_text(head + "forearm_hand_joint:\n      type: continuous" + tail, encoding="utf-8")
    out = tmp_path / "states.csv"
    msg = "{joint_names: [forearm_hand_joint], points: [{positions: [7.0], time_from_start: 3}]}"
    try:
        # the 2.3 rad/s start from rest plus a 1 m/s² base would tip it (ZMP 17 mm out,
        # tests/cli/test_tipover.py's subject): here the base stands still
        main(["simulate", str(spec), "--message", msg, "--output", str(out), "--base-accel", "0"])
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    assert code == 0, capsys.readouterr().err
    with out.open() as fh:
        last = list(csv.DictReader(fh))[-1]
    # the spec's gains (Kp 50) track to within the friction band 0.05 / 50 plus gravity sag
    assert float(last["forearm_hand_joint.position"]) == pytest.approx(7.0, abs=0.02)
