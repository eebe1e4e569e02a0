"""The whole robot in MuJoCo as `export mjcf --whole-robot --base free` writes it, on a floor.

The model is the export's (sim never writes another MJCF): bodies, inertias, joints,
collision geoms, the arm's `position` actuators (Kp, Kd, effort limit) and Gazebo
`mu1` as sliding friction. Added here through MuJoCo's model editor (MjSpec):

- contacts of time constant CONTACT_TIME;
- a ground plane at z = 0, the robot's lowest contact point on it (analysis.stance), with
  the exported scene's floor friction (export.mjcf_scene.FLOOR_FRICTION: 0, so that each
  contact takes the robot geom's own coefficient; MuJoCo combines two geoms by the larger
  one, Gazebo's ODE by the smaller, and its ground plane's mu is 100, so in both the
  robot's coefficient counts). A collision without
  Gazebo `mu1` keeps MuJoCo's default 1, which is Gazebo's default `mu` too. MuJoCo's
  friction is isotropic: a link whose `mu2` differs from `mu1` is noted, `mu1` is used;
- the plugin's motor on each drive wheel (drive.wheelmotor): a rotor the run spins at the
  commanded speed and a clutch, a friction-loss constraint of max_wheel_torque holding
  the wheel at the rotor's speed, as ODE's `vel`/`fmax` motor;
- sensors, so one copy of `sensordata` per step records the run: the arm and wheel
  joints' position, velocity and actuator force (a wheel's slot is filled by the run
  with its clutch torque, which no sensor reads), the root body's pose, and per
  ground-contact link its normal force (a `touch` site enclosing the link's geoms)
  and its height;
- the spec's sensors (sim.sensors.model): a site each, an IMU's MuJoCo sensors after
  the drive's, a camera's MuJoCo camera;
- the world's objects of a scene file (sim.world), static bodies with contact.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.analysis.stance import Stance
from armcli.drive.diffdrive import DriveParams
from armcli.drive.wheelmotor import add_wheel_motors, rotor_dofs
from armcli.errors import InputError
from armcli.export.mjcf import FREE_JOINT, build_mjcf
from armcli.export.mjcf_scene import FLOOR_FRICTION
from armcli.io.scene import Scene
from armcli.sim.sensors.model import add_sensors
from armcli.sim.world import WorldGeom, add_scene
from armcli.urdf.doc import Urdf

# [s] MuJoCo's contact time constant (solref, critically damped): its default, as the
# exported scene has it. Measured on the course robot (tests/drive/test_job.py): softer
# contacts (50 ms) stop the wheels' chatter but let the robot coast 2.5 % past its wheels'
# travel after a stop.
CONTACT_TIME = 0.02
TOUCH_MARGIN = 0.02  # [m] a touch site is the link's bounding sphere plus this


@dataclass(frozen=True)
class Layout:
    """Where each recorded quantity sits in `sensordata` (slices) and the model's indices."""

    arm_pos: slice
    arm_vel: slice
    arm_force: slice
    wheel_pos: slice  # left, right
    wheel_vel: slice
    wheel_force: slice
    base_pos: slice  # (x, y, z) of the root body [m]
    base_quat: slice  # (w, x, y, z)
    touch: slice  # one normal force [N] per contact link
    contact_pos: slice  # (x, y, z) [m] per contact link (its body origin)
    size: int


@dataclass(frozen=True)
class DriveModel:
    """The compiled MuJoCo model and what the run loop indexes into."""

    model: Any  # mujoco.MjModel
    arm_joints: tuple[str, ...]
    arm_qpos: np.ndarray  # (n,) int
    arm_act: np.ndarray  # (n,) int: the arm's position actuators; -1: a mimic joint follows
    wheel_qpos: np.ndarray  # (2,) int, left then right
    wheel_dof: np.ndarray  # (2,) int
    wheel_rotor: np.ndarray  # (2,) int: the motors' rotor dofs (drive.wheelmotor.spin)
    contacts: tuple[str, ...]  # ground-contact links
    layout: Layout
    base_z: float  # [m] the root body's height with the lowest contact on the floor
    notes: tuple[str, ...]
    world: tuple[WorldGeom, ...] = ()  # the scene's objects (sim.world)


def build_drive_model(
    urdf: Urdf,
    spec: Any,
    stance: Stance,
    params: DriveParams,
    arm_joints: tuple[str, ...],
    gains: tuple[np.ndarray, np.ndarray, np.ndarray],
    dt: float,
    meshes: dict[str, bytes] | None = None,
    world: Scene | None = None,
) -> DriveModel:
    """Compile the export's free-base model with floor, wheel motors and sensors.

    `gains`: the arm's (Kp, Kd, effort limit) as the run uses them (the spec's or the
    options'; effort inf: none). `world`: obstacles placed by sim.world.add_scene.
    """
    import mujoco

    exp = build_mjcf(urdf, spec, base="free", meshes=None)
    ms = mujoco.MjSpec.from_string(exp.model.decode("utf-8"), assets=dict(meshes or {}))
    ms.option.timestep = dt
    names = {j.name for j in ms.joints}
    for joint in (params.left_joint, params.right_joint):
        if joint not in names:
            raise InputError(
                f"diff-drive joint {joint!r} is not a moving joint of the robot",
                field="mobile_base.diff_drive",
            )
    ms.worldbody.add_geom(
        name="floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0.0, 0.0, 0.05],
        friction=list(FLOOR_FRICTION),
    )
    root = _root_body(ms)
    wheels = (params.left_joint, params.right_joint)
    motor_notes = add_wheel_motors(ms, wheels, params.max_torque, dt)
    driven = _arm_actuators(ms, arm_joints, gains)
    _sensors(ms, root, arm_joints, params, stance.ground.links)
    add_sensors(ms, getattr(spec, "sensors", {}))  # after the drive's: its Layout holds
    notes = [*_mu2_notes(urdf), *motor_notes]
    geoms = add_scene(ms, world) if world is not None else ()
    model = ms.compile()
    model.geom_solref[:] = (CONTACT_TIME, 1.0)
    arm_act = np.array(
        [model.actuator(driven[j]).id if j in driven else -1 for j in arm_joints], dtype=int
    )
    return DriveModel(
        model=model,
        arm_joints=arm_joints,
        arm_qpos=_qpos(model, arm_joints),
        arm_act=arm_act,
        wheel_qpos=_qpos(model, (params.left_joint, params.right_joint)),
        wheel_dof=np.array(
            [model.jnt_dofadr[model.joint(j).id] for j in (params.left_joint, params.right_joint)],
            dtype=int,
        ),
        wheel_rotor=rotor_dofs(model, wheels),
        contacts=stance.ground.links,
        layout=_layout(len(arm_joints), len(stance.ground.links)),
        base_z=-stance.ground.height,
        notes=tuple(notes),
        world=geoms,
    )


def _arm_actuators(
    ms: Any, joints: tuple[str, ...], gains: tuple[np.ndarray, np.ndarray, np.ndarray]
) -> dict[str, str]:
    """Joint -> its PD actuator: the export's `position` actuator with the run's gains.

    The export gives one to a joint with spec gains; a joint given gains by options only
    gets one here (the export's other actuator on it switched off); a mimic joint (an
    equality constraint to its leader, no actuator in the export) gets none.
    """
    import mujoco

    kp, kd, effort = gains
    followers = {str(e.name1) for e in ms.equalities}
    out = {}
    for i, joint in enumerate(joints):
        acts = [a for a in ms.actuators if a.target == joint]
        pd = next((a for a in acts if a.name == joint and a.biasprm[1] != 0.0), None)
        if pd is None and not acts and joint in followers:
            continue
        if pd is None:
            for a in acts:
                a.gainprm[0], a.biasprm[:3] = 0.0, 0.0
            pd = ms.add_actuator(
                name=f"{joint}_pd", target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT
            )
            if np.isfinite(effort[i]):
                pd.forcelimited = 1
                pd.forcerange = [-effort[i], effort[i]]
        pd.gaintype, pd.biastype = mujoco.mjtGain.mjGAIN_FIXED, mujoco.mjtBias.mjBIAS_AFFINE
        pd.gainprm[0] = kp[i]
        pd.biasprm[:3] = [0.0, -kp[i], -kd[i]]
        out[joint] = pd.name
    return out


def _root_body(ms: Any) -> Any:
    for body in ms.bodies:
        if any(j.name == FREE_JOINT for j in body.joints):
            return body
    raise InputError("the exported model has no free root body")  # export(base="free") has one


def _sensors(
    ms: Any, root: Any, arm: tuple[str, ...], p: DriveParams, contacts: tuple[str, ...]
) -> None:
    """In `Layout` order; each contact link gets a touch site around its body."""
    import mujoco

    S, Obj = mujoco.mjtSensor, mujoco.mjtObj
    wheels = (p.left_joint, p.right_joint)

    def add(kind: Any, objtype: Any, name: str) -> None:
        ms.add_sensor(type=kind, objtype=objtype, objname=name)

    for joints in (arm, wheels):
        for kind in (S.mjSENS_JOINTPOS, S.mjSENS_JOINTVEL, S.mjSENS_JOINTACTFRC):
            for j in joints:
                add(kind, Obj.mjOBJ_JOINT, j)
    add(S.mjSENS_FRAMEPOS, Obj.mjOBJ_XBODY, root.name)
    add(S.mjSENS_FRAMEQUAT, Obj.mjOBJ_XBODY, root.name)
    for link in contacts:
        body = ms.body(link)
        radius = max((_geom_reach(g) for g in body.geoms), default=0.0) + TOUCH_MARGIN
        body.add_site(
            name=f"{link}_touch",
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[radius, 0.0, 0.0],
            group=5,
        )
        add(S.mjSENS_TOUCH, Obj.mjOBJ_SITE, f"{link}_touch")
    for link in contacts:
        add(S.mjSENS_FRAMEPOS, Obj.mjOBJ_XBODY, link)


def _geom_reach(geom: Any) -> float:
    """[m] a bound on how far a geom reaches from its body's origin."""
    size = np.asarray(geom.size, dtype=float)
    return float(np.linalg.norm(np.asarray(geom.pos, dtype=float)) + np.linalg.norm(size))


def _layout(n: int, c: int) -> Layout:
    cuts = np.cumsum([0, n, n, n, 2, 2, 2, 3, 4, c, 3 * c])
    s = [slice(int(a), int(b)) for a, b in itertools.pairwise(cuts)]
    return Layout(s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8], s[9], int(cuts[-1]))


def _qpos(model: Any, joints: tuple[str, ...]) -> np.ndarray:
    return np.array([model.jnt_qposadr[model.joint(j).id] for j in joints], dtype=int)


def _mu2_notes(urdf: Urdf) -> list[str]:
    """Links whose Gazebo mu2 differs from mu1: MuJoCo's friction is isotropic."""
    out = []
    for g in urdf.gazebo:
        mu1, mu2 = g.values.get("mu1"), g.values.get("mu2")
        if mu1 is not None and mu2 is not None and mu1 != mu2:
            out.append(
                f"{g.reference}: Gazebo mu2 {mu2} differs from mu1 "
                f"{mu1}; MuJoCo's friction is isotropic, mu1 is used"
            )
    return out
