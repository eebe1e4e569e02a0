"""The IMU against physics and the run's ground truth.

- on the course base at rest: specific force (0, 0, +g) with MuJoCo's g = 9.81 m/s²
  (REP 145: an accelerometer at rest reads +g up) and no rate of turn;
- on a turntable spinning at 0.5 rad/s about z (a free hinge, nothing to slow it): the
  gyro reads (0, 0, 0.5) and the accelerometer, r from the axis, the centripetal
  -omega^2 r toward it plus +g: closed forms;
- on the course base turning in place: the gyro's z equals the mean rate of the
  ground-truth yaw over each sample period (the base itself wobbles about the command:
  its wheels slip), and the orientation equals the base's ground-truth orientation (the
  IMU sits on base_link, which base_footprint carries unrotated).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.robot.frames import quaternion_rpy
from armcli.sim.sensors.imu import ImuSampler
from armcli.sim.sensors.model import add_sensors
from tests.sim.sensors.drives import course_with, reading, run
from tests.sim.sensors.rigs import MOUNT, sensor

pytest.importorskip("mujoco")

G = 9.81  # [m/s²] MuJoCo's default gravity, the model's
ACC_TOL = 0.01  # [m/s²] the bound at rest
RATE_TOL = 0.01  # [rad/s] the bound in the turn
TRUTH_RATE_TOL = 1e-6  # [rad/s] the gyro's period mean against the truth's yaw difference
QUAT_TOL = 1e-9
SETTLE = 0.5  # [s] the robot starts with its contacts unloaded and settles within this
IMU = {"type": "imu", "link": "base_link", "rate": 100, "topic": "imu"}


def test_at_rest_the_imu_reads_plus_g_up_and_no_rate(tmp_path: Path) -> None:
    spec = course_with(tmp_path, {"imu": IMU})
    r = reading(run(spec, "commands:\n  - {linear: {x: 0.0}, time_from_start: 0.0}\n", 1.5), "imu")
    values = r.data["imu"][r.time >= SETTLE]
    assert len(values) == 101  # 100 Hz from 0.5 s to 1.5 s
    assert np.max(np.abs(values[:, 7:10] - [0.0, 0.0, G])) < ACC_TOL
    assert np.max(np.abs(values[:, 4:7])) < ACC_TOL  # [rad/s]


def test_on_a_turntable_at_half_a_radian_per_second(tmp_path: Path) -> None:
    import mujoco

    omega, radius, dt = 0.5, 0.3, 1e-3
    s = sensor(type="imu", origin={"xyz": [radius, 0.0, 0.1]})
    ms = mujoco.MjSpec()
    table = ms.worldbody.add_body(name=MOUNT, pos=[0.0, 0.0, 1.0])
    table.add_joint(type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0])
    table.add_geom(type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[0.5, 0.05, 0.0], mass=2.0)
    ms.option.timestep = dt
    add_sensors(ms, {"imu": s})
    model = ms.compile()
    data = mujoco.MjData(model)
    data.qvel[0] = omega
    record = []
    for _ in range(200):
        mujoco.mj_step(model, data)
        record.append(data.sensordata.copy())
    sampler = ImuSampler("imu", s, model, np.arange(10, 200, 10))
    values = sampler.reading(dt, np.array(record)).data["imu"]
    assert np.max(np.abs(values[:, 4:7] - [0.0, 0.0, omega])) < RATE_TOL
    assert np.max(np.abs(values[:, 4:7] - [0.0, 0.0, omega])) < TRUTH_RATE_TOL
    # the site's x points away from the axis: -omega^2 r along it, +g up
    expected = [-(omega**2) * radius, 0.0, G]
    assert np.max(np.abs(values[:, 7:10] - expected)) < TRUTH_RATE_TOL


def test_turning_in_place_the_gyro_reads_the_bases_rate(tmp_path: Path) -> None:
    spec = course_with(tmp_path, {"imu": IMU}, caster_mu=0.0)
    commands = "commands:\n  - {angular: {z: 0.5}, time_from_start: 0.0}\n"
    result = run(spec, commands, 3.0)
    r = reading(result, "imu")
    later = r.time >= 1.0  # the wheels' ramp (1 m/s²) is long over
    gyro = r.data["imu"][later, 4:7]
    assert abs(np.mean(gyro[:, 2]) - 0.5) < 2 * RATE_TOL  # the base turns 1-2 % slow (slip)
    # the truth: the base's yaw recorded every step, its change over each 10 ms period
    L = result.job.model.layout
    yaw = np.unwrap(quaternion_rpy(result.sensors[:, L.base_quat])[2])
    k = r.steps[later]
    truth = (yaw[k] - yaw[k - 10]) / (10 * result.job.dt)
    assert np.max(np.abs(gyro[:, 2] - truth)) < TRUTH_RATE_TOL


def test_the_orientation_is_the_bases_ground_truth(tmp_path: Path) -> None:
    spec = course_with(tmp_path, {"imu": IMU})
    commands = ("commands:\n  - {linear: {x: 0.3}, angular: {z: 0.4}, time_from_start: 0.0}\n"
                "  - {linear: {x: 0.0}, angular: {z: -0.6}, time_from_start: 1.0}\n")  # fmt: skip
    result = run(spec, commands, 2.0)
    r = reading(result, "imu")
    w, x, y, z = result.sensors[r.steps, result.job.model.layout.base_quat].T
    imu = r.data["imu"][:, :4]
    sign = np.sign(np.sum(imu * np.column_stack([x, y, z, w]), axis=1))  # q and -q: one turn
    assert np.max(np.abs(imu - sign[:, None] * np.column_stack([x, y, z, w]))) < QUAT_TOL
    assert np.ptp(quaternion_rpy(np.column_stack([w, x, y, z]))[2]) > 0.2  # it did turn
