"""The integral term ros-package adds: the arm under the written PID comes to rest at its poses.

Independent of armcli's engine: a few lines of Pinocchio forward dynamics (ABA) stepped
by semi-implicit Euler at 0.25 ms, the controller's PID (p, d, i with its clamp, as
control_toolbox computes it) held over each controller period, joint damping applied.
The period is the controller's, 1/`control.controller_update_rate` (1 ms in both example
specs), as gz_ros2_control holds the effort between updates (ros-controller-unstable
judges that loop stable: tests/analysis/test_rate.py). Reference values: the PD loop alone comes
to rest where analysis.sag says (0.028 rad off at `reach`), and with the integral term at
the commanded pose.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pytest

from armcli.analysis.sag import Hold, settle
from armcli.robot.model import Robot
from armcli.ros.holding import START_TOLERANCE, integral_terms, sag_at_poses
from armcli.spec.load import load_spec, loads_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.read import parse_urdf
from armcli.urdf.source import spec_urdfs
from tests.helpers import SPECS

PHYSICS_DT = 0.00025  # [s] the plant's step, a quarter of the controller's period
SETTLED = 1e-4  # [rad] at the pose after HOLD_S with the integral term
HOLD_S = 4.0  # [s]
PD_AGREEMENT = 0.01  # relative: the PD steady state against analysis.sag (no friction here)


def _robot(spec: RobotSpec) -> tuple[bytes, Robot]:
    """The URDF the controller drives (the whole robot, else the arm) and its Robot."""
    urdfs = spec_urdfs(spec)
    xml = urdfs.get(f"{spec.name}.urdf", urdfs["standalone_arm.urdf"])
    return xml, Robot.load(parse_urdf(xml, spec.name), strict=False)


Gains = Mapping[str, tuple[float, float, float, float]]  # joint -> p, d, i, i_clamp


def hold(robot: Robot, pose: Mapping[str, float], gains: Gains, period: float) -> float:
    """The largest |q - q_ref| after HOLD_S of a PID hold from rest at the pose [rad]."""
    import pinocchio as pin

    joints = list(gains)
    idx = [robot.joint(j).idx_v for j in joints]
    qidx = [robot.joint(j).idx_q for j in joints]
    p, d, i, clamp = (np.array([gains[j][k] for j in joints]) for k in range(4))
    damping = np.array([robot.joint(j).damping for j in joints])
    ref = np.array([pose[j] for j in joints])
    q, v = robot.q(robot.follow(dict(pose))), np.zeros(robot.model.nv)
    integral, tau = np.zeros(len(joints)), np.zeros(robot.model.nv)
    per = round(period / PHYSICS_DT)
    for step in range(round(HOLD_S / PHYSICS_DT)):
        if step % per == 0:  # the controller: PID on the state it reads, then held
            e = ref - q[qidx]
            integral = np.clip(integral + i * period * e, -clamp, clamp)
            tau[:] = 0.0
            tau[idx] = p * e - d * v[idx] + integral
        applied = tau.copy()
        applied[idx] -= damping * v[idx]
        v = v + PHYSICS_DT * pin.aba(robot.model, robot.data, q, v, applied)
        q = pin.integrate(robot.model, q, v * PHYSICS_DT)
    return float(np.max(np.abs(q[qidx] - ref)))


@pytest.mark.parametrize("spec_name", ["my_robot.yaml", "tabletop_arm.yaml"])
def test_written_pid_settles_at_every_pose(spec_name: str) -> None:
    spec = load_spec(SPECS / spec_name)
    xml, robot = _robot(spec)
    terms = integral_terms(spec, xml)
    assert sag_at_poses(spec, robot) > START_TOLERANCE and terms  # both specs sag without it
    gains = {j: (g.kp, g.kd, terms[j].i, terms[j].i_clamp) for j, g in spec.control.gains.items()}
    pd = {j: (g[0], g[1], 0.0, 0.0) for j, g in gains.items()}
    for name in spec.poses:
        pose = spec.pose(name)
        assert hold(robot, pose, gains, 1.0 / spec.control.controller_update_rate) < SETTLED, name
        expected = settle(robot, pose, Hold.pd(list(pd), [g[0] for g in pd.values()])).worst[1]
        got = hold(robot, pose, pd, 1.0 / spec.control.controller_update_rate)
        assert got == pytest.approx(expected, rel=PD_AGREEMENT, abs=1e-6), name


def test_no_integral_when_the_pd_gains_hold() -> None:
    text = (SPECS / "my_robot.yaml").read_text().replace("{kp: 50, kd: 1.5}", "{kp: 400, kd: 1.5}")
    spec = loads_spec(text)
    xml, robot = _robot(spec)
    assert sag_at_poses(spec, robot) < START_TOLERANCE  # 0.028 rad x 50 / 400
    assert integral_terms(spec, xml) == {}
