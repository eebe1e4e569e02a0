"""The drive against gazebo_ros_diff_drive (ROS 2) as an independent script would run it.

The reference here is written from the plugin's source (gazebo_ros_pkgs, branch ros2,
gazebo_plugins/src/gazebo_ros_diff_drive.cpp, `OnUpdate`), not from sim/diffdrive.py: it
steps the same compiled MuJoCo model (the export's, sim.drivemodel) with its own loop, so
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

import numpy as np
import pytest

from armcli.sim import drive
from armcli.sim.liftoff import roll_pitch_yaw
from armcli.sim.options import SimOptions
from armcli.spec.load import load_spec
from tests.helpers import DEFAULT_SPEC

pytest.importorskip("mujoco")

V, W, ARC_S = 0.2, 0.4, 5.0  # [m/s], [rad/s], [s]: the arc
# Same model, same steps, same controller rules: only floating-point order may differ.
# (The ROS 1 rule, "either wheel at speed", ends the arc 11.7 mm and 0.028 rad away.)
SAME_RUN_M, SAME_RUN_RAD = 1e-6, 1e-6
REACHED = 0.01  # [m/s] the plugin's literal


def _arc_file(tmp_path: Path) -> Path:
    path = tmp_path / "arc.yaml"
    path.write_text(
        f"commands:\n  - {{linear: {{x: {V}}}, angular: {{z: {W}}}, time_from_start: 0}}\n"
        f"  - {{time_from_start: {ARC_S}}}\n"
    )
    return path


def _plugin_reference(job: drive.DriveJob) -> tuple[float, float, float]:
    """The base's final (x, y, yaw) with the ROS 2 plugin's controller (module docstring)."""
    import mujoco

    dm, p, dt = job.model, job.params, job.dt
    m = dm.model
    d = mujoco.MjData(m)
    d.qpos[2] = dm.base_z
    d.qpos[dm.arm_qpos] = job.arm.q0
    held = dm.arm_act >= 0
    d.ctrl[dm.arm_act[held]] = job.arm.q0[held]  # the arm holds its start pose (Kd * 0)
    r, half = p.radius, p.separation / 2.0
    instructed = np.zeros(2)  # wheel_speed_instr_ [m/s]
    last = 0.0
    steps = round(job.duration / dt)
    for k in range(steps):
        now = (k + 1) * dt  # Gazebo's sim time when OnUpdate runs before step k
        elapsed = now - last
        if elapsed >= p.period - 1e-12:
            lin, ang = (V, W) if now < ARC_S else (0.0, 0.0)
            target = np.array([lin - ang * half, lin + ang * half])
            current = d.qvel[dm.wheel_dof] * r
            if p.max_accel == 0 or np.all(np.abs(target - current) < REACHED):
                d.ctrl[dm.wheel_act] = target / r
            else:
                step = p.max_accel * elapsed
                instructed += np.clip(target - current, -step, step)
                d.ctrl[dm.wheel_act] = instructed / r
            last = now
        mujoco.mj_step(m, d)
    yaw = roll_pitch_yaw(d.qpos[3:7].reshape(1, 4))[2][0]
    return float(d.qpos[0]), float(d.qpos[1]), float(yaw)


def _arc(spec: Path, tmp_path: Path) -> tuple[drive.DriveJob, drive.DriveRun]:
    job = drive.prepare(load_spec(spec), SimOptions(duration=ARC_S + 1.0), _arc_file(tmp_path))
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
    yaw = roll_pitch_yaw(run.sensors[-1:, L.base_quat])[2][0]
    rx, ry, ryaw = _plugin_reference(job)
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
