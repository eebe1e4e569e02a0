"""`armcli simulate specs/rover.yaml --cmd-vel ... --world ... -o run.mcap`: the sensors' topics
read back by rosbags (its own MCAP reader and CDR decoder, ROS 2 Jazzy's definitions), and the
sensor inputs the command refuses.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from armcli.sim.sensors.rays import Pinhole
from armcli.spec.load import load_spec
from tests.helpers import SPECS, run_main

pytest.importorskip("mujoco")

ROVER = SPECS / "rover.yaml"
WORLD = SPECS / "rover" / "world.yaml"
DRIVE = SPECS / "trajectories" / "rover" / "drive.yaml"
DURATION = 1.0  # [s]
# topic -> (schema, frame_id, rate [Hz]): the spec's sensors as gazebo_ros publishes them
TOPICS = {
    "/scan": ("sensor_msgs/msg/LaserScan", "lidar_link", 10),
    "/front_camera/depth/image_raw": ("sensor_msgs/msg/Image", "camera_link_optical", 10),
    "/front_camera/points": ("sensor_msgs/msg/PointCloud2", "camera_link_optical", 10),
    "/front_camera/camera_info": ("sensor_msgs/msg/CameraInfo", "camera_link_optical", 10),
    "/imu": ("sensor_msgs/msg/Imu", "base_link", 100),
}


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    from mcap.reader import make_reader
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    from armcli.cli import main

    out = tmp_path_factory.mktemp("rover") / "run.mcap"
    args = [
        "simulate",
        ROVER,
        "--cmd-vel",
        DRIVE,
        "--world",
        WORLD,
        "--duration",
        DURATION,
        "-o",
        out,
    ]
    with pytest.raises(SystemExit) as exc:
        main([str(a) for a in args])
    assert exc.value.code == 0
    store = get_typestore(Stores.ROS2_JAZZY)
    msgs: dict[str, list[tuple[int, Any]]] = {}
    with Reader(out) as reader:
        for conn, t, raw in reader.messages():
            msgs.setdefault(conn.topic, []).append((t, store.deserialize_cdr(raw, conn.msgtype)))
    with out.open("rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None
    schemas = {ch.topic: summary.schemas[ch.schema_id] for ch in summary.channels.values()}
    return {"msgs": msgs, "schemas": schemas, "store": store}


def test_each_sensor_topic_has_its_schema_frame_and_rate(bag: dict[str, Any]) -> None:
    from rosbags.typesys import get_types_from_msg

    for topic, (schema, frame, rate) in TOPICS.items():
        s = bag["schemas"][topic]
        assert s.name == schema
        for name, (consts, fields) in get_types_from_msg(s.data.decode(), s.name).items():
            assert (consts, fields) == tuple(bag["store"].fielddefs[name][:2]), name
        msgs = bag["msgs"][topic]
        assert {m.header.frame_id for _, m in msgs} == {frame}
        # one message per period 1/rate from t = 0 to the end, log time = header stamp
        expected = [round(i * 1e9 / rate) for i in range(int(DURATION * rate) + 1)]
        assert [t for t, _ in msgs] == expected, topic
        assert [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for _, m in msgs] == expected


def test_the_scan_and_the_camera_describe_the_spec(bag: dict[str, Any]) -> None:
    spec = load_spec(ROVER)
    li = spec.sensors["base_scan"].lidar
    cam = spec.sensors["front_depth"].camera
    assert li is not None and cam is not None
    scan = bag["msgs"]["/scan"][0][1]
    assert (scan.angle_min, scan.angle_max) == pytest.approx((li.min_angle, li.max_angle))
    assert scan.angle_increment == pytest.approx((li.max_angle - li.min_angle) / (li.samples - 1))
    assert (scan.range_min, scan.range_max, len(scan.ranges)) == pytest.approx(
        (li.range_min, li.range_max, li.samples)
    )
    finite = np.asarray(scan.ranges)[np.isfinite(scan.ranges)]
    assert np.all((finite >= li.range_min) & (finite <= li.range_max))
    assert np.isinf(scan.ranges).any()  # the open side of the world: no return is +inf
    info = bag["msgs"]["/front_camera/camera_info"][0][1]
    np.testing.assert_allclose(np.reshape(info.k, (3, 3)), Pinhole.of(cam).K)
    assert (info.width, info.height, info.distortion_model) == (cam.width, cam.height, "plumb_bob")
    image = bag["msgs"]["/front_camera/depth/image_raw"][0][1]
    assert (image.encoding, image.width, image.height, image.step) == ("32FC1", 160, 120, 640)
    depth = np.frombuffer(bytes(image.data), dtype="<f4").reshape(120, 160)
    cloud = bag["msgs"]["/front_camera/points"][0][1]
    assert (cloud.height, cloud.width, cloud.point_step, cloud.is_dense) == (120, 160, 12, False)
    points = np.frombuffer(bytes(cloud.data), dtype="<f4").reshape(120, 160, 3)
    seen = np.isfinite(depth)
    assert seen.any() and np.array_equal(np.isfinite(points[..., 2]), seen)
    np.testing.assert_allclose(points[..., 2][seen], depth[seen])  # the cloud's z is the depth


def test_the_imu_reads_gravity_and_the_world_is_in_the_file(bag: dict[str, Any]) -> None:
    # driving on the level floor its height does not change: on average it reads +g up
    z = [m.linear_acceleration.z for t, m in bag["msgs"]["/imu"] if t >= 0.2e9]
    assert np.mean(z) == pytest.approx(9.81, abs=0.05)
    ((_, world),) = bag["msgs"]["/world"]
    assert sorted(m.ns for m in world.markers) == ["crate_left", "crate_right", "post", "wall"]
    assert {m.header.frame_id for m in world.markers} == {"world"}


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("    link: lidar_link\n", "    link: nowhere_link\n", "sensors.base_scan.link"),
        ("    type: lidar\n", "    type: sonar\n", "sensors.base_scan.type"),
    ],
)
def test_a_bad_sensor_is_exit_2_naming_file_and_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, field: str
) -> None:
    spec = tmp_path / "rover.yaml"
    text = ROVER.read_text()
    assert old in text
    spec.write_text(text.replace(old, new, 1))
    out = tmp_path / "run.mcap"
    code, _, err = run_main(["simulate", spec, "--cmd-vel", DRIVE, "-o", out], capsys)
    assert code == 2
    assert str(spec) in err and field in err
    assert not out.exists()


def test_the_foxglove_layout_names_topics_the_run_has(bag: dict[str, Any]) -> None:
    import json

    layout = json.loads((SPECS / "rover" / "foxglove_layout.json").read_text())
    named = set()
    for panel in layout["configById"].values():
        named |= set(panel.get("topics", {}))
        mode = panel.get("imageMode", {})
        named |= {mode[k] for k in ("imageTopic", "calibrationTopic") if k in mode}
        named |= {p["value"].split(".")[0] for p in panel.get("paths", [])}
    assert named and named <= set(bag["msgs"])
