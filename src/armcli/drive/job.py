"""Drive the whole robot on its wheels in MuJoCo while the arm follows its trajectory.

What `armcli simulate SPEC --cmd-vel drive.yaml` runs: the robot as `export mjcf` writes
it (drive.model) standing on a floor under gravity; its base driven by
gazebo_ros_diff_drive's controller (drive.diffdrive) from the /cmd_vel commands
(drive.cmdvel); its arm under the PD law, gains, gravity compensation and reference of
`simulate` (sim.job prepares them as for the fixed-base engine) through the export's
position actuators: ctrl = q_ref + (Kd / Kp) v_ref (+ g(q) / Kp with gravity
compensation, the fixed-base arm's g as the controller computes it), so the actuator
force Kp (q_ref - q) + Kd (v_ref - v) + g is clipped at the effort limit as a whole.

Every step's sensors are kept (one copy of `sensordata`); odometry, tipping and lift-off
are computed from them after the run (analysis.liftoff), the outputs by drive.output.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from armcli.analysis.stance import NoStance, Stance, stance_of
from armcli.drive.cmdvel import CmdVel, load_cmd_vel
from armcli.drive.diffdrive import DiffDriveController, DriveParams, Odometry, encoder_odometry
from armcli.drive.model import DriveModel, build_drive_model
from armcli.drive.step import SEEN, Steps
from armcli.drive.wheelmotor import clutch_torque
from armcli.errors import InputError, SimulationError
from armcli.io.scene import Scene
from armcli.robot.file import floating_of
from armcli.sim import job as simjob
from armcli.sim.job import SimJob
from armcli.sim.options import SimOptions
from armcli.sim.sensors.reading import Reading
from armcli.sim.sensors.rig import make_rig
from armcli.sim.simulate import steps_of
from armcli.sim.tipping import whole_robot
from armcli.sim.world import load_world, refuse_overlaps
from armcli.urdf.doc import Urdf
from armcli.urdf.source import RobotFile

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec
    from armcli.spec.sensors import Sensor

SETTLE_EXTRA_S = 2.0  # [s] simulated after the last command or trajectory point by default
MAX_DRIVE_STEPS = 600_000  # every step's sensors are kept: ~150 MB for the course robot
PROGRESS_STEPS = 10_000  # steps between progress reports


@dataclass(frozen=True)
class DriveJob:
    """Everything a drive run needs, validated."""

    arm: SimJob  # the arm's gains, reference, start, dt, output rate, tool point
    cmd: CmdVel
    params: DriveParams
    model: DriveModel
    stance: Stance  # the whole robot on its contacts (static tipping angle)
    robot: Urdf  # the whole robot's URDF (MCAP /robot_description, replay)
    duration: float  # [s]
    sensors: Mapping[str, Sensor] = field(default_factory=dict)  # simulated (sim.sensors)

    @property
    def dt(self) -> float:
        """[s] the time step."""
        return self.arm.config.dt


def prepare(
    file: RobotFile,
    opts: SimOptions,
    cmd_vel: Path | CmdVel,
    *,
    gate: Callable[[Urdf], None] | None = None,
    world: Path | Scene | None = None,
    sensors: bool = True,
    params: DriveParams | None = None,
) -> DriveJob:
    """Validate the inputs and build the model; InputError names what is wrong.

    `file`: a spec's robot file (`RobotFile.of_spec`; the drive runs its whole robot).
    Without a trajectory the arm holds its start pose. `gate` sees the whole robot's URDF
    first and may refuse it (the command passes check.gate.refuse_check_errors). `world`:
    a scene file (or its Scene) whose objects the robot drives among (sim.world); one the
    robot stands in at the start is refused. `sensors`: simulate the spec's sensors.
    `params`: the diff drive when the spec's `mobile_base.diff_drive` does not state it (a
    URDF's plugin kept verbatim by import). `cmd_vel`: a file, or commands already read.
    """
    spec = _driven_spec(file)
    params = params if params is not None else DriveParams.of(spec)
    cmd = cmd_vel if isinstance(cmd_vel, CmdVel) else load_cmd_vel(cmd_vel)
    rate = opts.rate if opts.rate is not None else params.update_rate
    hold = opts.duration if opts.duration is not None else 1.0  # 0 is refused, as elsewhere
    job = simjob.prepare(file, replace(opts, rate=rate, duration=hold), hold=True)
    robot = whole_robot(file)
    if gate is not None:
        gate(robot)
    duration = opts.duration
    if duration is None:
        duration = max(job.trajectory.duration, cmd.duration) + SETTLE_EXTRA_S
    if duration / job.config.dt > MAX_DRIVE_STEPS:
        raise InputError(
            f"{duration:g} s at dt = {job.config.dt:g} s is more than {MAX_DRIVE_STEPS:,} "
            "steps, the most a drive run records",
            field="SimOptions.duration",
        )
    job = replace(job, duration=float(duration))
    links = set(spec.mobile_base.links) if spec.mobile_base else None
    stance = stance_of(robot, candidates=links, floating=floating_of(file, robot))
    if isinstance(stance, NoStance):
        raise InputError(f"the robot cannot stand: {stance.reason}", field="mobile_base")
    n = len(job.robot.names)
    kp = np.broadcast_to(np.asarray(job.config.kp, dtype=float), (n,))
    kd = np.broadcast_to(np.asarray(job.config.kd, dtype=float), (n,))
    gains = (kp, kd, np.asarray(job.robot.effort, dtype=float))
    if isinstance(world, Path):
        world = load_world(world, [lk.name for lk in robot.links])
    model = build_drive_model(
        robot, spec, stance, params, job.robot.names, gains, job.config.dt, world=world
    )
    if world is not None:
        refuse_overlaps(model.model, start_data(model, job.q0), model.world, world.source)
    kept = dict(spec.sensors) if sensors else {}
    return DriveJob(job, cmd, params, model, stance, robot, float(duration), kept)


def start_data(dm: DriveModel, q0: np.ndarray) -> Any:
    """MuJoCo's data at the start: the robot at rest on the floor at the origin, arm at q0."""
    import mujoco

    d = mujoco.MjData(dm.model)
    d.qpos[2] = dm.base_z
    d.qpos[dm.arm_qpos] = q0
    mujoco.mj_forward(dm.model, d)
    return d


def _driven_spec(file: RobotFile) -> RobotSpec:
    """The spec whose whole robot drives; InputError for a URDF (no diff drive to run)."""
    if file.spec is None or not file.compiled:
        raise InputError(
            "drives a spec's robot (its mobile_base.diff_drive); give a spec instead of a URDF",
            field="cmd_vel",
        )
    return file.spec


@dataclass(frozen=True)
class DriveRun:
    """A run's every state: sensors (DriveModel.layout), reference, odometry."""

    job: DriveJob
    t: np.ndarray  # (N + 1,) [s]
    sensors: np.ndarray  # (N + 1, layout.size): state k's sensors (forces: of step k)
    q_ref: np.ndarray  # (N + 1, n) the arm's reference
    v_ref: np.ndarray
    wheel_command: np.ndarray  # (N + 1, 2) [rad/s] the joint speeds the plugin set
    odometry: Odometry
    wall_time: float  # [s] spent stepping
    readings: tuple[Reading, ...] = ()  # the sensors' (sim.sensors)
    notes: tuple[str, ...] = ()  # what the sensors could not do

    @property
    def steps(self) -> int:
        """Steps of the run."""
        return len(self.t) - 1


def update_steps(steps: int, dt: float, period: float) -> np.ndarray:
    """Steps at whose start the plugin updates.

    Gazebo's sim time then is (k + 1) dt, and it acts once at least `period` has passed
    since its last update (the first: since 0).
    """
    out, last = [], 0.0
    for k in range(steps):
        now = (k + 1) * dt
        if now - last >= period - 1e-12:
            out.append(k)
            last = now
    return np.array(out, dtype=np.int64)


class Pilot(Protocol):
    """Closes the loop a drive otherwise runs open: the commands, and when the arm moves.

    A path follower (plan.mobile.pursuit) gives /cmd_vel at every plugin update from the
    state as it is, instead of the job's file, and may hold the arm's reference until the
    base has arrived. Between two updates the drive steps without it (`drive.step`) and
    then shows it what each step started from (`observe`).
    """

    def command(self, t: float, data: Any) -> tuple[float, float]:
        """(linear.x [m/s], angular.z [rad/s]) at the plugin update at time t [s]."""
        ...

    def arm_steps(self, k0: int, k1: int) -> np.ndarray:
        """For steps k0 .. k1 - 1: which step's arm reference to use (<= k: the arm waits)."""
        ...

    def observe(self, k0: int, seen: np.ndarray) -> None:
        """The states steps k0 .. k0 + len(seen) - 1 started from (`drive.step.SEEN`)."""
        ...


def run(
    job: DriveJob,
    progress: Callable[[int, int], None] | None = None,
    pilot: Pilot | None = None,
) -> DriveRun:
    """Step the model for the job's duration from rest on the floor (`pilot`: closed loop)."""
    import mujoco

    m, dm, arm = job.model.model, job.model, job.arm
    d = start_data(dm, arm.q0)
    steps = steps_of(job.duration, job.dt)
    t = np.arange(steps + 1) * job.dt
    q_ref, v_ref = arm.reference.sample(t)
    kp, kd = np.asarray(arm.config.kp, dtype=float), np.asarray(arm.config.kd, dtype=float)
    ctrl_arm = q_ref + np.divide(kd, kp, out=np.zeros_like(kp), where=kp > 0) * v_ref
    inv_kp = np.divide(1.0, kp, out=np.zeros_like(kp), where=kp > 0)  # Kp 0: no g through ctrl
    updates = update_steps(steps, job.dt, job.params.period)
    now = (updates + 1) * job.dt  # Gazebo's sim time at each update
    lin, ang = job.cmd.at(now)
    elapsed = np.diff(now, prepend=0.0)  # the plugin's seconds_since_last_update
    rec = np.empty((steps + 1, m.nsensordata))  # the Layout's, then the sensors' (IMU)
    wheel_cmd = np.zeros((steps + 1, 2))
    controller = DiffDriveController(job.params)
    cols = np.nonzero(dm.arm_act >= 0)[0]  # a mimic joint follows its leader: no actuator
    stepper = Steps(
        m,
        d,
        dm,
        np.ascontiguousarray(ctrl_arm[:, cols]),
        inv_kp[cols],
        cols,
        arm.robot if arm.config.gravity_comp else None,
        rec,
        np.empty((steps + 1, SEEN)),
    )
    command = np.zeros(2)
    used = np.arange(steps + 1)  # the arm reference's step at each step (a pilot may hold it)
    rig = make_rig(job.sensors, m, steps, job.dt)
    ends = _chunk_ends(steps, updates, rig.due)
    start = time.perf_counter()
    k0 = u = 0
    for k1 in ends.tolist():
        if u < len(updates) and updates[u] == k0:
            twist = (lin[u], ang[u]) if pilot is None else pilot.command(float(now[u]), d)
            command = controller.update(twist[0], twist[1], d.qvel[dm.wheel_dof], elapsed[u])
            u += 1
        if pilot is not None:
            used[k0:k1] = pilot.arm_steps(k0, k1)
        wheel_cmd[k0:k1] = command
        stepper.advance(k0, k1, used[k0:k1], command)
        if pilot is not None:
            pilot.observe(k0, stepper.seen[k0:k1])
        if rig.due[k1 - 1]:
            rig.sample(k1 - 1, m, d)
        if progress is not None and k1 // PROGRESS_STEPS > k0 // PROGRESS_STEPS:
            progress(k1 // PROGRESS_STEPS * PROGRESS_STEPS, steps)
        k0 = k1
    due, sample, rotor, wheel_force = rig.due, rig.sample, dm.wheel_rotor, dm.layout.wheel_force
    mujoco.mj_forward(m, d)
    rec[steps], wheel_cmd[steps] = d.sensordata, command
    rec[steps, wheel_force] = clutch_torque(d, rotor)
    if due[steps]:
        sample(steps, m, d)
    if pilot is not None and steps:
        used[steps] = min(used[steps - 1] + 1, steps)
        q_ref, v_ref = q_ref[used], v_ref[used]
    wall = time.perf_counter() - start
    _refuse_reset(d, rec, job.dt)
    wl = rec[:-1, dm.layout.wheel_vel]
    odom = encoder_odometry(wl[:, 0], wl[:, 1], job.dt, job.params.radius, job.params.separation)
    return DriveRun(
        job, t, rec, q_ref, v_ref, wheel_cmd, odom, wall, rig.readings(job.dt, rec), rig.notes
    )


def _refuse_reset(d: Any, rec: np.ndarray, dt: float) -> None:
    """MuJoCo resets a state that became non-finite and goes on: such a run is no result."""
    import mujoco

    W = mujoco.mjtWarning
    bad = [
        w for w in (W.mjWARN_BADQACC, W.mjWARN_BADQPOS, W.mjWARN_BADQVEL) if d.warning[w].number > 0
    ]
    if bad:
        rows = np.nonzero(~np.all(np.isfinite(rec), axis=1))[0]
        step = int(rows[0]) if rows.size else None
        raise SimulationError(
            "MuJoCo's state became non-finite and was reset",
            time=step * dt if step is not None else None,
            step=step,
            cause="gains too high for dt, or a model MuJoCo cannot integrate (try a smaller --dt)",
        )


def _chunk_ends(steps: int, updates: np.ndarray, due: np.ndarray) -> np.ndarray:
    """Where the steps between two plugin updates end: at each update, after each sensor sample."""
    ends = np.concatenate([updates, np.nonzero(due[:steps])[0] + 1, [steps]])
    return np.unique(ends[ends > 0])
