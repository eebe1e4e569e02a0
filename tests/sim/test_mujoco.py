"""armcli's simulator against a second engine: MuJoCo on the same URDF and trajectory.

MuJoCo's Euler integrator treats dof damping implicitly, which is the same scheme armcli
uses for Kd + damping, so the D gain is moved into `dof_damping` and the rest of the PD
torque is applied through `qfrc_applied` each step. Contacts are disabled (MuJoCo would
collide the arm's own geoms); the test trajectory stays away from the joint stops.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from armcli.robot.model import Robot
from armcli.sim.simulate import SimConfig, simulate, simulated
from armcli.trajectory.message import loads_trajectory
from armcli.trajectory.reference import build_reference
from tests.helpers import load_robot

mujoco = pytest.importorskip("mujoco")

DT = 5e-4  # [s] the comparison step
KP, KD = 50.0, 5.0  # the spec's gains
AGREE = 3e-4  # [rad] required agreement with friction off (the bound)
FRICTION_DIFF = 2e-3  # [rad] with friction on (measured 7.9e-4): MuJoCo friction is soft
MULTI = (
    "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
    " - {positions: [0.6, 0.4], time_from_start: 1.0}\n"
    " - {positions: [0.9, 1.2], time_from_start: 2.0}\n"
    " - {positions: [0.9, 1.2], time_from_start: 2.5}\n"
    " - {positions: [0.5, 0.8], time_from_start: 3.5}\n"
    " - {positions: [0.3, 0.3], time_from_start: 5.0}\n"
)  # specs/trajectories/pick.yaml, ending at (0.3, 0.3) instead of on the stops
Q0 = np.array([0.2, 0.2])
DURATION = 6.0


def mujoco_model(urdf: Path, friction: bool) -> object:
    xml = urdf.read_text(encoding="utf-8").replace(
        "</robot>",
        '<mujoco><compiler discardvisual="true" fusestatic="false"/></mujoco></robot>',
    )
    m = mujoco.MjModel.from_xml_string(xml)
    m.opt.timestep = DT
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    m.dof_damping[:] = m.dof_damping + KD  # implicit D gain, as in armcli
    if not friction:
        m.dof_frictionloss[:] = 0.0
    return m


def mujoco_run(m: object, q_ref: np.ndarray, v_ref: np.ndarray) -> np.ndarray:
    d = mujoco.MjData(m)
    d.qpos[:] = Q0
    out = np.empty_like(q_ref)
    out[0] = d.qpos
    for k in range(q_ref.shape[0] - 1):
        d.qfrc_applied[:] = KP * (q_ref[k] - d.qpos) + KD * v_ref[k]
        mujoco.mj_step(m, d)
        out[k + 1] = d.qpos
    return out


@pytest.fixture(scope="module")
def arm(built_dir: Path) -> Robot:
    return simulated(load_robot(built_dir / "standalone_arm.urdf"))


def _both(arm: Robot, built_dir: Path, friction: bool) -> tuple[np.ndarray, np.ndarray]:
    tr = loads_trajectory(MULTI, dict.fromkeys(arm.names, (0.0, math.pi / 2)))
    ref = build_reference(tr, arm.names, Q0)
    plant = arm if friction else arm.with_limits(friction=np.zeros(2))
    cfg = SimConfig(np.full(2, KP), np.full(2, KD), dt=DT)
    res = simulate(plant, ref, Q0, DURATION, cfg)
    assert not res.stop_active.any() and not res.saturated.any()  # same physics on both sides
    q_mj = mujoco_run(
        mujoco_model(built_dir / "standalone_arm.urdf", friction), res.q_ref, res.v_ref
    )
    return res.q, q_mj


def test_agrees_with_mujoco_without_friction(arm: Robot, built_dir: Path) -> None:
    q, q_mj = _both(arm, built_dir, friction=False)
    assert np.max(np.abs(q - q_mj)) < AGREE


def test_friction_difference_with_mujoco_is_small(arm: Robot, built_dir: Path) -> None:
    # MuJoCo solves frictionloss as a soft (regularised) constraint, armcli as a hard
    # stiction/velocity-level one, so they differ slightly where the joints stick.
    q, q_mj = _both(arm, built_dir, friction=True)
    assert np.max(np.abs(q - q_mj)) < FRICTION_DIFF
