"""Sensors in a drive: when they sample, what a scan sees at a wall, what a run may keep.

- driven into a wall, the base stops at it (its contact) and the lidar's closest range is
  the truth: the wall's face from the scene file minus where the lidar is (the base's
  ground-truth pose and the sensor's origin), along the ray nearest the wall's normal;
- each sensor samples at its own rate from t = 0 (sim.states' sample_steps);
- a run whose sensors would keep more than the bound is refused before it starts.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from armcli.errors import InputError
from armcli.robot.frames import quaternion_rpy
from armcli.sim.sensors.rays import lidar_directions
from tests.sim.sensors.drives import course_with, reading, run

pytest.importorskip("mujoco")

RANGE_TOL = 1e-3  # [m] the bound
CONTACT_TOL = 5e-3  # [m] MuJoCo's soft contact: the base presses into the wall by mm
WALL_X = 1.2  # [m] the wall's face
LIDAR_XYZ = (0.28, 0.0, 0.25)  # on base_link, over the front of its box (top at z = 0.2)
LIDAR = {"type": "lidar", "link": "base_link", "origin": {"xyz": list(LIDAR_XYZ)}, "rate": 10,
         "topic": "scan", "lidar": {"samples": 360, "min_angle": -math.pi,
                                    "max_angle": math.pi * 358 / 360, "range_min": 0.01,
                                    "range_max": 8.0, "resolution": 1e-4}}  # fmt: skip
WALL = ("collision_objects:\n  - id: wall\n    primitives: [{type: box, dimensions: [0.2, 4, 1]}]\n"
        f"    primitive_poses: [{{position: {{x: {WALL_X + 0.1}, z: 0.5}}}}]\n")  # fmt: skip


def test_driven_into_a_wall_the_closest_range_is_the_truth(tmp_path: Path) -> None:
    spec = course_with(tmp_path, {"front": LIDAR})
    result = run(spec, "commands:\n  - {linear: {x: 0.4}, time_from_start: 0.0}\n", 3.5, WALL)
    L = result.job.model.layout
    x_base = result.sensors[:, L.base_pos][:, 0]
    assert x_base[-1] == pytest.approx(WALL_X - 0.3, abs=CONTACT_TOL)  # box front: 0.3 ahead
    scan = reading(result, "front")
    for j in (0, len(scan.steps) // 2, len(scan.steps) - 1):
        k = scan.steps[j]
        pos, quat = result.sensors[k, L.base_pos], result.sensors[k, L.base_quat]
        roll, pitch, yaw = (float(a[0]) for a in quaternion_rpy(quat[None, :]))
        assert abs(roll) < 0.01 and abs(pitch) < 0.01  # level: the wall's distance is planar
        c, s = math.cos(yaw), math.sin(yaw)
        lidar_x = pos[0] + c * LIDAR_XYZ[0] - s * LIDAR_XYZ[1]
        li = result.job.sensors["front"].lidar
        assert li is not None
        dirs = lidar_directions(li)
        angle = np.arctan2(dirs[:, 1], dirs[:, 0]) + yaw
        ahead = np.cos(angle) > 0.1  # the rays towards the wall (behind: the arm)
        truth = np.min((WALL_X - lidar_x) / np.cos(angle[ahead]))
        seen = scan.data["ranges"][j].reshape(-1)[ahead]
        assert float(np.min(seen)) == pytest.approx(truth, abs=RANGE_TOL)


def test_each_sensor_samples_at_its_rate_from_zero(tmp_path: Path) -> None:
    imu = {"type": "imu", "link": "base_link", "rate": 40, "topic": "imu"}
    spec = course_with(tmp_path, {"front": {**LIDAR, "rate": 7}, "imu": imu})
    result = run(spec, "commands:\n  - {linear: {x: 0.0}, time_from_start: 0.0}\n", 1.0)
    # periods 1/7 s and 1/40 s from 0, each time on the nearest 1 ms step
    np.testing.assert_allclose(reading(result, "front").time, np.round(np.arange(7 + 1) / 7, 3))
    np.testing.assert_allclose(reading(result, "imu").time, np.arange(41) / 40)


def test_sensors_keeping_too_much_are_refused_before_the_run(tmp_path: Path) -> None:
    big = {"type": "depth_camera", "link": "base_link", "rate": 1000, "topic": "depth",
           "camera": {"width": 4000, "height": 3000, "horizontal_fov": 1.0}}  # fmt: skip
    spec = course_with(tmp_path, {"depth": big})
    with pytest.raises(InputError, match="more than the 250 MB a run keeps") as exc:
        run(spec, "commands:\n  - {linear: {x: 0.0}, time_from_start: 0.0}\n", 1.0)
    assert exc.value.field == "sensors.depth"
