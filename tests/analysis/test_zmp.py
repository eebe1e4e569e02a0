"""The whole robot's zero-moment point against closed forms and MuJoCo's contact forces.

MuJoCo reference: the course robot exported to MJCF (armcli.export) with a free base on
a floor, its wheels locked (the model holds the base still, as braked wheels do), the
arm driven by the exported position actuators along a trajectory. Every 10 ms,
MuJoCo's centre of pressure of the floor contact forces is compared with our point from
MuJoCo's own arm state (q, v, a): two engines, one motion.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from armcli.analysis import zmp as zmps
from armcli.analysis.stance import Payload, Stance, stance_of
from armcli.compiler.expand import expand_urdfs
from armcli.spec.load import load_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.doc import Urdf
from armcli.urdf.read import parse_urdf
from tests.helpers import DEFAULT_SPEC, FIXTURES

ARM = ("arm_base_forearm_joint", "forearm_hand_joint")
WHEELS = ("base_right_wheel_joint", "base_left_wheel_joint")
G = 9.81  # [m/s²] Pinocchio's and MuJoCo's default gravity
EXACT = 1e-10  # [m]
# [m] ZMP vs MuJoCo's CoP, in the base's frame. The model's wheels are rigid; MuJoCo's
# contacts are springs, so its base rocks on them (pitch accelerations ~0.2 rad/s² in the
# swing) and the CoP moves with that rocking. The difference shrinks with the contacts'
# time constant: 2.3 mm at MuJoCo's default 20 ms, 1.4 mm at 5 ms, 0.8 mm at 2 ms (dt 0.5 ms),
# which the swing test uses.
MUJOCO_TOL = 1e-3
CONTACT_TIME = 2e-3  # [s] MuJoCo's solref time constant: stiff, near-rigid wheels
MUJOCO_DT = 5e-4  # [s] MuJoCo wants the time constant >= 2 steps
SETTLE_S = 1.0  # [s] MuJoCo's robot settles into its soft contacts before the swing


@pytest.fixture(scope="module")
def course() -> tuple[RobotSpec, Urdf, Stance]:
    spec = load_spec(DEFAULT_SPEC)
    urdf = parse_urdf(expand_urdfs(spec)["my_robot.urdf"], "my_robot.urdf")
    stance = stance_of(urdf, candidates=set(spec.mobile_base.links),
                       payload=Payload(0.0, "hand_link", (0.0, 0.0, 0.3)))  # fmt: skip
    assert isinstance(stance, Stance)
    return spec, urdf, stance


def series_at(stance: Stance, q: np.ndarray, v: np.ndarray, a: np.ndarray, accel: float = 0.0):
    """The point at one state: two kept steps whose velocity difference is a dt."""
    dt = 1e-3
    t, kept = np.array([0.0, dt]), np.array([0, 1])
    qs, vs = np.array([q, q]), np.array([v, v + a * dt])
    return zmps.zmp_series(stance, ARM, t, kept, qs, vs, dt, accel, 0.02)


def test_at_rest_it_is_the_centre_of_mass(course: tuple[RobotSpec, Urdf, Stance]) -> None:
    _, _, stance = course
    q = np.array([0.7, 0.9])
    s = series_at(stance, q, np.zeros(2), np.zeros(2), accel=2.0)
    import pinocchio as pin

    c = pin.centerOfMass(
        stance.model, stance.model.createData(), stance.q(dict(zip(ARM, q, strict=True)))
    )
    h = c[2] - stance.ground.height
    assert s.zmp[0, 0] == pytest.approx(c[:2], abs=EXACT)
    # accelerating at a: f_z = m g, the moment about y grows by m h a: x moves back by h a / g
    assert s.zmp[0, 1] == pytest.approx([c[0] - h * 2.0 / G, c[1]], abs=EXACT)
    assert s.zmp[0, 2] == pytest.approx([c[0] + h * 2.0 / G, c[1]], abs=EXACT)


def test_largest_base_acceleration_puts_it_on_the_edge(
    course: tuple[RobotSpec, Urdf, Stance],
) -> None:
    _, _, stance = course
    q = np.array([1.2, 0.3])
    s = series_at(stance, q, np.zeros(2), np.zeros(2))
    a_max = zmps.max_base_accel(s, stance.polygon, 0.0)
    at = series_at(stance, q, np.zeros(2), np.zeros(2), accel=a_max)
    assert min(at.margin[0, 1:]) == pytest.approx(0.0, abs=EXACT)


def _mujoco_model(spec: RobotSpec, urdf: Urdf, tmp: Path, gravity: tuple[float, float, float]):
    mujoco = pytest.importorskip("mujoco")
    from lxml import etree

    from armcli.export.mjcf import build_mjcf
    from armcli.export.mjcf_scene import scene_xml

    root = etree.fromstring(build_mjcf(urdf, spec, base="free").model)
    equality = root.find("equality")
    if equality is None:
        equality = etree.SubElement(root, "equality")
    for j in WHEELS:  # braked wheels: each held at its start angle
        etree.SubElement(equality, "joint", joint1=j, polycoef="0 0 0 0 0")
    (tmp / "robot.xml").write_bytes(etree.tostring(root))
    (tmp / "scene.xml").write_bytes(scene_xml("robot.xml", "robot"))
    m = mujoco.MjModel.from_xml_path(str(tmp / "scene.xml"))
    m.opt.gravity[:] = gravity
    m.opt.timestep = MUJOCO_DT
    m.geom_solref[:, 0] = CONTACT_TIME
    # The model's contacts do not slide; the scene's floor has friction 0, so each geom's
    # own coefficient counts, and the caster's 0.1 would slide in the swing: every contact
    # grips here (MuJoCo's default 1), as the model assumes.
    m.geom_friction[:, 0] = 1.0
    return mujoco, m


def _centre_of_pressure(mujoco, m, d) -> tuple[np.ndarray, float]:
    floor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    num, den, f6 = np.zeros(2), 0.0, np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        if floor not in (c.geom1, c.geom2):
            continue
        mujoco.mj_contactForce(m, d, i, f6)
        f = c.frame.reshape(3, 3).T @ f6[:3]  # on geom2, world frame
        f = -f if c.geom2 == floor else f
        num, den = num + c.pos[:2] * f[2], den + f[2]
    base = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "base_footprint")
    R, x = d.xmat[base].reshape(3, 3), d.xpos[base]
    p = np.array([*(num / den), 0.0])
    return (R.T @ (p - x))[:2], den  # in the base's frame, where the model holds it


def _arm_state(mujoco, m, d) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in ARM]
    qa, va = [m.jnt_qposadr[i] for i in ids], [m.jnt_dofadr[i] for i in ids]
    return d.qpos[qa].copy(), d.qvel[va].copy(), d.qacc[va].copy()


def test_zmp_agrees_with_mujoco_along_a_fast_swing(
    course: tuple[RobotSpec, Urdf, Stance], tmp_path: Path
) -> None:
    from armcli.trajectory.message import load_trajectory
    from armcli.trajectory.reference import build_reference

    spec, urdf, stance = course
    mujoco, m = _mujoco_model(spec, urdf, tmp_path, (0.0, 0.0, -G))
    d = mujoco.MjData(m)
    traj = load_trajectory(
        FIXTURES / "tipover" / "swing.yaml", dict.fromkeys(ARM, (0.0, math.pi / 2))
    )
    ref = build_reference(traj, ARM, np.zeros(2))
    gains = [spec.control.gains[j] for j in ARM]
    lead = np.array([g.kd / g.kp for g in gains])  # the exported actuator's ctrl (export/mjcf.py)
    ours, theirs = [], []
    steps = round((SETTLE_S + traj.duration + 0.5) / m.opt.timestep)
    for k in range(steps):
        t = max(0.0, k * m.opt.timestep - SETTLE_S)
        q_ref, v_ref = ref.sample(np.array([t]))
        d.ctrl[:] = q_ref[0] + lead * v_ref[0]
        mujoco.mj_forward(m, d)  # contact forces and qacc of this state
        if t > 0 and k % 20 == 0:
            q, v, a = _arm_state(mujoco, m, d)
            ours.append(series_at(stance, q, v, a).zmp[0, 0])
            theirs.append(_centre_of_pressure(mujoco, m, d)[0])
        mujoco.mj_step(m, d)
    ours_a, theirs_a = np.array(ours), np.array(theirs)
    assert np.ptp(ours_a[:, 0]) > 0.03  # the swing moves the point by centimetres
    assert np.max(np.linalg.norm(ours_a - theirs_a, axis=1)) < MUJOCO_TOL


def test_base_acceleration_agrees_with_mujoco(
    course: tuple[RobotSpec, Urdf, Stance], tmp_path: Path
) -> None:
    """Accelerating at a is, in the base's frame, gravity leaning by (-a, 0, -g)."""
    spec, urdf, stance = course
    a = 3.0
    mujoco, m = _mujoco_model(spec, urdf, tmp_path, (-a, 0.0, -G))
    d = mujoco.MjData(m)
    q = np.array([0.6, 0.8])
    d.ctrl[:] = q
    for _ in range(round(SETTLE_S / m.opt.timestep)):
        mujoco.mj_step(m, d)
    mujoco.mj_forward(m, d)
    qm, _, _ = _arm_state(mujoco, m, d)
    cop, _ = _centre_of_pressure(mujoco, m, d)
    s = series_at(stance, qm, np.zeros(2), np.zeros(2), accel=a)
    assert s.zmp[0, 1] == pytest.approx(cop, abs=MUJOCO_TOL)
