"""Lidar scans and depth images against closed-form geometry.

- a 360-ray lidar in a world of boxes and cylinders: every range equals the closed-form
  ray-box or ray-cylinder distance (tests/sim/sensors/rigs.py, written from the scene
  file's numbers) within 1 mm, and a ray that hits nothing reads +inf (REP 117);
- a depth camera facing a wall at an angle: every point of the image lies on the wall's
  plane within 1 mm, and pixel (u, v) maps through K back to the ray that produced it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from armcli.sim.sensors import scanners
from armcli.sim.sensors.rays import Pinhole, lidar_directions
from tests.sim.sensors.rigs import boxes_and_cylinders, ray_box, ray_cylinder, sensor, stage

pytest.importorskip("mujoco")

RANGE_TOL = 1e-3  # [m] the bound on a range against the closed form
PLANE_TOL = 1e-3  # [m] the bound on a depth point off the wall's plane
RESOLUTION = 1e-4  # [m] the lidar's rounding, well inside RANGE_TOL
BOXES = [
    (3.0, 0.5, 0.5, 0.4, 2.0, 1.0),
    (-2.0, -1.0, 0.5, 1.0, 0.6, 1.0),
    (0.5, -4.0, 0.5, 3.0, 0.2, 1.0),
]
CYLINDERS = [(0.0, 2.5, 0.5, 1.0, 0.3), (-1.5, 2.0, 0.25, 0.5, 0.2)]
MOUNT = (0.2, 0.1, 0.4)  # [m] the lidar's body; the sensor 0.05 m above it
LIDAR = {"samples": 360, "min_angle": -math.pi, "max_angle": math.pi * 358 / 360,
         "range_min": 0.1, "range_max": 6.0, "resolution": RESOLUTION}  # fmt: skip


def _closed_form(o: np.ndarray, d: np.ndarray) -> float:
    hits = [ray_box(o, d, np.array(b[:3]), np.array(b[3:]) / 2) for b in BOXES]
    hits += [ray_cylinder(o, d, np.array(c[:3]), c[3], c[4]) for c in CYLINDERS]
    best = min(hits)
    return best if best <= LIDAR["range_max"] else math.inf


@pytest.mark.parametrize("yaw", [0.0, 0.7])
def test_lidar_ranges_equal_closed_form_ray_box_and_cylinder(tmp_path: Path, yaw: float) -> None:
    s = sensor(type="lidar", origin={"xyz": [0, 0, 0.05]}, lidar=LIDAR)
    model, data = stage(tmp_path, boxes_and_cylinders(BOXES, CYLINDERS), {"scan": s}, MOUNT, yaw)
    sampler = scanners.LidarSampler("scan", s, model, np.array([0]))
    sampler.sample(0, model, data)
    ranges = sampler.ranges[0, 0].astype(float)
    o = np.array(MOUNT) + np.array([0, 0, 0.05])
    c, sn = math.cos(yaw), math.sin(yaw)
    R = np.array([[c, -sn, 0], [sn, c, 0], [0, 0, 1]])
    assert s.lidar is not None
    expected = np.array([_closed_form(o, R @ d) for d in lidar_directions(s.lidar)])
    assert len(ranges) == 360
    assert np.array_equal(np.isinf(ranges), np.isinf(expected))  # no return: +inf, REP 117
    assert 0 < np.isinf(expected).sum() < 360  # some rays see nothing, most see something
    hit = np.isfinite(expected)
    assert np.max(np.abs(ranges[hit] - expected[hit])) < RANGE_TOL


def test_a_lidar_sees_nothing_nearer_than_range_min(tmp_path: Path) -> None:
    # a box 5 cm ahead: the rays start at range_min 0.1 inside it and see its far face
    near_box = boxes_and_cylinders([(0.1, 0.0, 0.5, 0.1, 0.1, 1.0)], [])
    s = sensor(type="lidar", origin={"xyz": [0, 0, 0.45]}, lidar={**LIDAR, "samples": 3,
               "min_angle": -0.01, "max_angle": 0.01})  # fmt: skip
    model, data = stage(tmp_path, near_box, {"scan": s})
    sampler = scanners.LidarSampler("scan", s, model, np.array([0]))
    sampler.sample(0, model, data)
    # the far face is at x = 0.15; rays at +-0.01 rad reach it 0.15 / cos(0.01) out
    assert sampler.ranges[0, 0, 1] == pytest.approx(0.15, abs=RANGE_TOL)


def _wall(x: float) -> str:
    return boxes_and_cylinders([(x + 0.1, 0.0, 3.0, 0.2, 20.0, 6.0)], [])


@pytest.mark.parametrize("native", [True, False])
def test_depth_points_lie_on_the_wall_and_pixels_map_through_K(
    tmp_path: Path, native: bool
) -> None:
    cam = {"width": 64, "height": 48, "horizontal_fov": 1.2, "near": 0.05, "far": 10.0}
    # turned 0.4 rad left and pitched 0.2 rad down: the wall x = 2 is at an angle to the image
    s = sensor(type="depth_camera", origin={"xyz": [0, 0, 0.5], "rpy": [0, 0.2, 0.4]},
               camera=cam)  # fmt: skip
    model, data = stage(tmp_path, _wall(2.0), {"cam": s}, (0.0, 0.0, 0.3))
    sampler = scanners.DepthSampler("cam", s, model, np.array([0]))
    if not native:
        sampler.native = None
    elif sampler.native is None:
        pytest.skip("armcli.sim._raycast is not built (make native)")
    sampler.sample(0, model, data)
    depth = sampler.depth[0].astype(float)
    assert s.camera is not None
    pin = Pinhole.of(s.camera)
    v, u = np.mgrid[0 : pin.height, 0 : pin.width]
    # K^-1 (u, v, 1) times the depth: the point in the optical frame, from the message alone
    xyz = np.linalg.solve(pin.K, np.stack([u.ravel(), v.ravel(), np.ones(u.size)])) * depth.ravel()
    site = data.site("sensor/cam")
    R_world_optical = site.xmat.reshape(3, 3) @ np.array([[0, 0, 1], [-1, 0, 0], [0, -1, 0]])
    world = (R_world_optical @ xyz).T + site.xpos
    seen = np.isfinite(depth.ravel())
    off_wall, off_floor = np.abs(world[seen, 0] - 2.0), np.abs(world[seen, 2])
    # every point on the wall's plane x = 2 or on the floor z = 0, most on the wall
    assert np.max(np.minimum(off_wall, off_floor)) < PLANE_TOL
    assert np.sum(off_wall < PLANE_TOL) > 0.5 * depth.size
