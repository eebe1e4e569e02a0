"""`view --replay run.mcap` with sensors: the scans and clouds read back, placed where they were.

A short drive of specs/rover.yaml among its world's boxes is written as an MCAP; read back,
each scan topic's returns equal the run's own (range times the ray), and in the viewer, at
a scan's time, its points carried by the replayed base pose land on the world points the
run recorded (the lidar's recorded pose times the rays): the frames are right end to end.
In a real browser (headless Chromium) the scan's orange dots and the world's boxes show.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pytest

from armcli.drive.api import drive_robot
from armcli.sim.options import SimOptions
from armcli.sim.rosbag import load_replay
from armcli.sim.sensors.messages import scan_points
from armcli.sim.sensors.replay import load_sensor_replay
from armcli.view.browser import Viewer
from tests.helpers import SPECS, spec_file
from tests.view.test_browser import browser, colour_masks, save, wait_for  # noqa: F401

pytest.importorskip("mujoco")

ROVER = SPECS / "rover.yaml"
POINT_TOL = 1e-5  # [m] float32 points, float64 poses
PAINT_TIMEOUT_S = 60.0


@pytest.fixture(scope="module")
def drove(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("replay") / "run.mcap"
    driven = drive_robot(spec_file(ROVER), SimOptions(duration=1.5),
                         SPECS / "trajectories" / "rover" / "drive.yaml",
                         world=SPECS / "rover" / "world.yaml")  # fmt: skip
    out.write_bytes(driven.files(out, None)[out])
    scan = next(r for r in driven.run.readings if r.name == "base_scan")
    robot = driven.job.robot
    joints = [j.name for j in robot.joints if j.type != "fixed"]
    return {"path": out, "scan": scan, "joints": joints, "urdf": robot.text.decode()}


def test_scans_clouds_and_world_read_back(drove: dict[str, Any]) -> None:
    replay = load_sensor_replay(drove["path"])
    frames = {t.topic: t.frame for t in replay.tracks}
    assert frames == {"/scan": "lidar_link", "/front_camera/points": "camera_link_optical"}
    track = next(t for t in replay.tracks if t.topic == "/scan")
    scan = drove["scan"]
    np.testing.assert_allclose(track.time, scan.time)
    for j in range(len(scan.time)):
        np.testing.assert_allclose(track.points[j], scan_points(scan, j), atol=POINT_TOL)
    assert sorted(s.kind for s in replay.world) == ["box", "box", "box", "cylinder"]


def test_the_viewer_puts_a_scan_where_the_lidar_saw_it(drove: dict[str, Any]) -> None:
    run = load_replay(drove["path"], drove["joints"])
    sensors = load_sensor_replay(drove["path"])
    scan = drove["scan"]
    j = len(scan.time) - 1
    with Viewer(drove["urdf"], replay=run, sensors=sensors, port=0) as v:
        v.seek(float(scan.time[j]))
        assert v._sensors is not None
        local = np.asarray(v._sensors.handles["/scan"].points, dtype=np.float64)
        base = run.base_at(float(scan.time[j]))
    assert base is not None
    position, wxyz = base
    R = _matrix(wxyz)
    world = local @ R.T + position
    pose = scan.data["pose"][j]
    expected = scan_points(scan, j) @ pose[3:].reshape(3, 3).T + pose[:3]
    np.testing.assert_allclose(world, expected, atol=1e-4)  # the base pose: interpolated, 1e-9


def test_the_browser_shows_the_scan_and_the_world(drove: dict[str, Any], browser: Any) -> None:  # noqa: F811
    run = load_replay(drove["path"], drove["joints"])
    sensors = load_sensor_replay(drove["path"])
    with Viewer(drove["urdf"], replay=run, sensors=sensors, port=0) as v:
        v.seek(1.0)
        dev = browser(v.url)

        def drawn(img: np.ndarray) -> bool:
            r, g, b = img[..., 0], img[..., 1], img[..., 2]
            orange = (r > 200) & (g > 80) & (g < 170) & (b < 60)
            return bool(orange.sum() > 30 and colour_masks(img)["blue"].sum() > 200)

        img = wait_for(dev, drawn, PAINT_TIMEOUT_S)
        save(img, "viewer_rover_scan.png")
        assert drawn(img)
        time.sleep(0.1)


def _matrix(wxyz: np.ndarray) -> np.ndarray:
    w, x, y, z = wxyz
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip
