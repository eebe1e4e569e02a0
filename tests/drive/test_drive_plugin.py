"""The drive against gazebo_ros_diff_drive (ROS 2) as an independent script would run it.

The reference here is written from the plugin's source (gazebo_ros_pkgs, branch ros2,
gazebo_plugins/src/gazebo_ros_diff_drive.cpp, `OnUpdate`), not from drive/diffdrive.py: it
steps the same compiled MuJoCo model (the export's, drive.model) with its own loop, so
the only thing compared is the controller and its timing. Its rules, from the source:

- Gazebo advances the sim time before `OnUpdate`, which acts once `update_period` has
  passed since its last action (`simTime - last_update_time_ < update_period_`: return)
  and then sets `last_update_time_ = simTime`;
- with `max_wheel_acceleration` 0, or BOTH wheels' rim speeds within 0.01 m/s of their
  targets, the joints get their targets; otherwise each wheel's instructed speed moves by
  `target - measured`, clipped to `max_wheel_acceleration * seconds_since_last_update`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from armcli.drive import job as drive
from armcli.robot.frames import quaternion_rpy
from armcli.sim.options import SimOptions
from tests.helpers import DEFAULT_SPEC, spec_file

pytest.importorskip("mujoco")

V, W, ARC_S = 0.2, 0.4, 5.0  # [m/s], [rad/s], [s]: the arc
# Same model, same steps, same controller rules: only floating-point order may differ.
# (The ROS 1 rule, "either wheel at speed", ends the arc 11.7 mm and 0.028 rad away.)
SAME_RUN_M, SAME_RUN_RAD = 1e-6, 1e-6
REACHED = 0.01  # [m/s] the plugin's literal
SCENE_AGREES = 1e-6  # [m, rad] the same bodies and contacts from the files (measured: equal)


def _arc_file(tmp_path: Path) -> Path:
    path = tmp_path / "arc.yaml"
    path.write_text(
        f"commands:\n  - {{linear: {{x: {V}}}, angular: {{z: {W}}}, time_from_start: 0}}\n"
        f"  - {{time_from_start: {ARC_S}}}\n"
    )
    return path


Commands = tuple[tuple[float, float, float], ...]  # (from time [s], linear.x, angular.z)
ARC: Commands = ((0.0, V, W), (ARC_S, 0.0, 0.0))


def _plugin_reference(job: drive.DriveJob, commands: Commands = ARC, model: Any = None) -> Any:
    """The final MjData of the plugin's controller (module docstring) driving `model`.

    `model`: the drive's own (default) or another compiled model with the same joint and
    actuator names (the exported scene); the arm holds its start pose (Kd * 0).
    """
    import mujoco

    dm, p, dt = job.model, job.params, job.dt
    m = dm.model if model is None else model
    d = mujoco.MjData(m)
    wheels = (p.left_joint, p.right_joint)
    wheel_dof = [m.jnt_dofadr[m.joint(j).id] for j in wheels]
    rotor = [m.jnt_dofadr[m.joint(f"{j}_rotor").id] for j in wheels]  # the motors' speed
    d.qpos[2] = dm.base_z
    for j, q in zip(job.arm.robot.names, job.arm.q0, strict=True):
        d.qpos[m.jnt_qposadr[m.joint(j).id]] = q
    for i in dm.arm_act[dm.arm_act >= 0]:
        name = dm.model.actuator(int(i)).name
        d.ctrl[m.actuator(name).id] = job.arm.q0[list(dm.arm_act).index(i)]
    r, half = p.radius, p.separation / 2.0
    instructed = np.zeros(2)  # wheel_speed_instr_ [m/s]
    vel = np.zeros(2)  # the joints' motor speed [rad/s]: SetParam("vel")
    last = 0.0
    for k in range(round(job.duration / dt)):
        now = (k + 1) * dt  # Gazebo's sim time when OnUpdate runs before step k
        elapsed = now - last
        if elapsed >= p.period - 1e-12:
            lin, ang = next(((v, w) for t0, v, w in reversed(commands) if now >= t0), (0, 0))
            target = np.array([lin - ang * half, lin + ang * half])
            current = d.qvel[wheel_dof] * r
            if p.max_accel == 0 or np.all(np.abs(target - current) < REACHED):
                vel = target / r
            else:
                step = p.max_accel * elapsed
                instructed += np.clip(target - current, -step, step)
                vel = instructed / r
            last = now
        d.qvel[rotor] = vel
        mujoco.mj_step(m, d)
    return d


def _pose(d: Any) -> tuple[float, float, float]:
    """(x, y, yaw) of the free base."""
    yaw = quaternion_rpy(d.qpos[3:7].reshape(1, 4))[2][0]
    return float(d.qpos[0]), float(d.qpos[1]), float(yaw)


def _arc(spec: Path, tmp_path: Path) -> tuple[drive.DriveJob, drive.DriveRun]:
    job = drive.prepare(spec_file(spec), SimOptions(duration=ARC_S + 1.0), _arc_file(tmp_path))
    return job, drive.run(job)


def _spec_with(tmp_path: Path, old: str, new: str) -> Path:
    text = DEFAULT_SPEC.read_text()
    assert text.count(old) == 1
    path = tmp_path / "my_robot.yaml"
    path.write_text(text.replace(old, new))
    return path


def _assert_follows_the_plugin(job: drive.DriveJob, run: drive.DriveRun) -> None:
    L = job.model.layout
    x, y, _ = run.sensors[-1, L.base_pos]
    yaw = quaternion_rpy(run.sensors[-1:, L.base_quat])[2][0]
    rx, ry, ryaw = _pose(_plugin_reference(job))
    assert (x, y) == pytest.approx((rx, ry), abs=SAME_RUN_M)
    assert yaw == pytest.approx(ryaw, abs=SAME_RUN_RAD)


def test_an_arc_follows_the_ros2_plugin(tmp_path: Path) -> None:
    _assert_follows_the_plugin(*_arc(DEFAULT_SPEC, tmp_path))


def test_max_wheel_acceleration_0_is_no_limit(tmp_path: Path) -> None:
    """The plugin's default (`max_wheel_acceleration` absent: 0): targets at once."""
    spec = _spec_with(tmp_path, "    wheel_diameter: 0.2\n",
                      "    wheel_diameter: 0.2\n    max_wheel_acceleration: 0\n")  # fmt: skip
    job, run = _arc(spec, tmp_path)
    assert job.params.max_accel == 0.0
    _assert_follows_the_plugin(job, run)
    first = drive.update_steps(run.steps, job.dt, job.params.period)[0]
    r, half = job.params.radius, job.params.separation / 2.0
    # the first update commands the targets themselves, no ramp
    assert run.wheel_command[first] == pytest.approx([(V - W * half) / r, (V + W * half) / r])


def _exported_scene(job: drive.DriveJob, spec: Path, tmp_path: Path) -> Any:
    """`export mjcf --whole-robot --base free`'s scene.xml, with the plugin's wheel motors."""
    import mujoco

    from armcli.drive.wheelmotor import add_wheel_motors
    from armcli.export.mjcf_files import export_mjcf

    export_mjcf(spec, tmp_path / "out" / "robot.xml", base="free", whole_robot=True)
    ms = mujoco.MjSpec.from_file(str(tmp_path / "out" / "scene.xml"))
    p = job.params
    add_wheel_motors(ms, (p.left_joint, p.right_joint), p.max_torque, job.dt)
    return ms.compile()


def test_the_exported_scene_drives_as_simulate_cmd_vel(tmp_path: Path) -> None:
    """The floor rule: the caster's mu 0.1 counts in both (export.mjcf_scene.FLOOR_FRICTION)."""
    straight = ((0.0, 0.3, 0.0), (4.0, 0.0, 0.0))  # the 1.2 m
    path = tmp_path / "straight.yaml"
    path.write_text("commands:\n  - {linear: {x: 0.3}, time_from_start: 0}\n"
                    "  - {time_from_start: 4.0}\n")  # fmt: skip
    job = drive.prepare(spec_file(DEFAULT_SPEC), SimOptions(duration=5.0), path)
    x, y, yaw = _pose(_plugin_reference(job, straight))
    assert x == pytest.approx(1.2, rel=0.02)  # the commanded distance
    sx, sy, syaw = _pose(
        _plugin_reference(job, straight, _exported_scene(job, DEFAULT_SPEC, tmp_path))
    )
    assert (sx, sy, syaw) == pytest.approx((x, y, yaw), abs=SCENE_AGREES)


FAST = "commands:\n  - {linear: {x: 1.0}, time_from_start: 0.5}\n  - {time_from_start: 2.5}\n"
HOLDS = 5e-4  # relative: ODE's motor holds its speed exactly; the clutch measured 4e-5
NEWTON = 0.10  # relative: the ramp's torque against m a r / 2 + I a / r (measured 5 %)
# relative: the motor's stand-in parameters x0.01-x100 move the 2 m drive by <= 0.1 %
# (measured); the velocity actuator it replaced drove 6.5 % further at twice its gain
STAND_IN = 2e-3


def _fast(tmp_path: Path) -> drive.DriveRun:
    path = tmp_path / "fast.yaml"
    path.write_text(FAST)
    return drive.run(drive.prepare(spec_file(DEFAULT_SPEC), SimOptions(duration=3.5), path))


def test_the_wheels_hold_their_speed_and_carry_newtons_torque(tmp_path: Path) -> None:
    """1 m/s after a 1 m/s² ramp (the spec's max_wheel_acceleration), held for 1 s."""
    run = _fast(tmp_path)
    job, s, t = run.job, run.sensors, run.t
    L = job.model.layout
    hold = (t > 1.7) & (t < 2.4)
    speed = np.mean(s[hold][:, L.wheel_vel], axis=0)
    assert speed == pytest.approx([1.0 / job.params.radius] * 2, rel=HOLDS)
    # the encoder integral of the plugin's symmetric ramps: the commanded 1 m/s x 2 s
    assert run.odometry.x[-1] == pytest.approx(2.0, rel=HOLDS)
    ramp = (t > 0.7) & (t < 1.4)
    x = s[:, L.base_pos][:, 0]
    accel = np.polyfit(t[ramp], np.gradient(x, t)[ramp], 1)[0]  # [m/s²] the base's, measured
    r, mass = job.params.radius, job.stance.mass
    inertia = _wheel_inertia(job)
    newton = (mass / 2.0 * r + inertia / r) * accel  # each wheel: half the robot, its own spin
    extra = np.mean(s[ramp][:, L.wheel_force], axis=0) - np.mean(s[hold][:, L.wheel_force], axis=0)
    assert extra == pytest.approx([newton] * 2, rel=NEWTON)


def _wheel_inertia(job: drive.DriveJob) -> float:
    """[kg·m²] the left wheel body's inertia about its axis (MuJoCo's model)."""
    import mujoco

    m = job.model.model
    jid = m.joint(job.params.left_joint).id
    body = m.jnt_bodyid[jid]
    axis = m.jnt_axis[jid]  # in the body frame; body inertia in its inertial frame
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, m.body_iquat[body])
    a = R.reshape(3, 3).T @ axis
    return float(a @ (m.body_inertia[body] * a))


@pytest.mark.parametrize(
    ("armature", "solref", "solimp"),
    [(10.0, 2.0, None), (1e5, 2.0, None), (1e3, 4.0, None), (1e3, 2.0, (0.9, 0.95))],
    ids=["armature/100", "armature*100", "solref*2", "mujoco-solimp"],
)
def test_the_motor_stand_in_parameters_do_not_matter(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    armature: float,
    solref: float,
    solimp: tuple[float, float] | None,
) -> None:
    from armcli.drive import wheelmotor

    base = _fast(tmp_path)
    monkeypatch.setattr(wheelmotor, "ROTOR_ARMATURE", armature)
    monkeypatch.setattr(wheelmotor, "CLUTCH_SOLREF", solref)
    if solimp is not None:
        monkeypatch.setattr(wheelmotor, "CLUTCH_SOLIMP", (*solimp, 0.001, 0.5, 2.0))
    other = _fast(tmp_path)
    L = base.job.model.layout
    x0 = base.sensors[-1, L.base_pos][0] - base.sensors[0, L.base_pos][0]
    x1 = other.sensors[-1, L.base_pos][0] - other.sensors[0, L.base_pos][0]
    assert x1 == pytest.approx(x0, rel=STAND_IN)
