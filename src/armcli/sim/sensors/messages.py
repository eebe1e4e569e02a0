"""A run's sensor readings as the ROS 2 topics Gazebo's plugins publish (sensors.cdr bytes).

The topics are the spec's, as compiler.sensors remaps them for gazebo_ros: a lidar's
`/TOPIC` (sensor_msgs/LaserScan for one ring, PointCloud2 for several: x, y, z of each
return in the sensor frame, no-returns left out), a depth camera's
`/TOPIC/depth/image_raw` (Image 32FC1 [m]), `/TOPIC/points` (PointCloud2 in the optical
frame, organised as the image, NaN where there is no return) and `/TOPIC/camera_info`, a
camera's `/TOPIC/image_raw` and `/TOPIC/camera_info`, an IMU's `/TOPIC` (Imu). Each is
stamped with the sample's simulated time and the sensor's `frame` (default its link).
"""

from __future__ import annotations

import numpy as np

from armcli.sim import rosbag
from armcli.sim.sensors import cdr
from armcli.sim.sensors.camera import encoding
from armcli.sim.sensors.imu import variances
from armcli.sim.sensors.rays import Pinhole, angle_increment, lidar_directions
from armcli.sim.sensors.reading import Reading

LASER_SCAN = "sensor_msgs/msg/LaserScan"
POINT_CLOUD = "sensor_msgs/msg/PointCloud2"
IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
IMU = "sensor_msgs/msg/Imu"
SENSOR_QOS_DEPTH = 10


def channels(readings: tuple[Reading, ...]) -> list[rosbag.Channel]:
    """The topics of every reading, in sensor-name order."""
    out = []
    for r in readings:
        stamps = [round(float(t) * 1e9) for t in r.time]
        for topic, datatype, messages in _topics(r, stamps):
            out.append(
                rosbag.Channel(
                    topic,
                    datatype,
                    rosbag.qos(SENSOR_QOS_DEPTH, False),
                    list(zip(stamps, messages, strict=True)),
                )
            )
    return out


def _topics(r: Reading, stamps: list[int]) -> list[tuple[str, str, list[bytes]]]:
    s, frame, base = r.sensor, r.sensor.frame_id, "/" + r.sensor.topic
    if s.type == "lidar":
        assert s.lidar is not None
        if s.lidar.is_3d:
            return [(base, POINT_CLOUD, _lidar_clouds(r, stamps))]
        return [(base, LASER_SCAN, _scans(r, stamps))]
    if s.type == "imu":
        var = variances(s)
        return [
            (
                base,
                IMU,
                [
                    cdr.imu(ns, frame, row, var)
                    for ns, row in zip(stamps, r.data["imu"], strict=True)
                ],
            )
        ]
    assert s.camera is not None
    pin = Pinhole.of(s.camera)
    size = (pin.width, pin.height)
    info = [cdr.camera_info(ns, frame, size, pin.K) for ns in stamps]
    if s.type == "camera":
        kind = encoding(s)
        images = [
            cdr.image(ns, frame, kind, img if kind != "mono8" else img[..., 0])
            for ns, img in zip(stamps, r.data["image"], strict=True)
        ]
        return [(f"{base}/image_raw", IMAGE, images), (f"{base}/camera_info", CAMERA_INFO, info)]
    depth = r.data["depth"]
    rays = pin.optical_rays().reshape(pin.height, pin.width, 3)
    images = [cdr.image(ns, frame, "32FC1", d) for ns, d in zip(stamps, depth, strict=True)]
    clouds = [
        cdr.point_cloud(ns, frame, _optical_points(rays, d), dense=False)
        for ns, d in zip(stamps, depth, strict=True)
    ]
    return [
        (f"{base}/depth/image_raw", IMAGE, images),
        (f"{base}/points", POINT_CLOUD, clouds),
        (f"{base}/camera_info", CAMERA_INFO, info),
    ]


def _optical_points(rays: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """(h, w, 3) points z * (x_n, y_n, 1); NaN where the depth is not finite."""
    z = np.where(np.isfinite(depth), depth, np.nan)
    return np.asarray(rays * z[..., None], dtype=np.float32)


def _scans(r: Reading, stamps: list[int]) -> list[bytes]:
    li = r.sensor.lidar
    assert li is not None
    angles = (
        li.min_angle,
        li.max_angle,
        angle_increment(li),
        0.0,
        1.0 / r.sensor.rate,
        li.range_min,
        li.range_max,
    )
    frame = r.sensor.frame_id
    return [
        cdr.laser_scan(ns, frame, angles, ranges[0])
        for ns, ranges in zip(stamps, r.data["ranges"], strict=True)
    ]


def _lidar_clouds(r: Reading, stamps: list[int]) -> list[bytes]:
    li = r.sensor.lidar
    assert li is not None
    dirs = lidar_directions(li)
    out = []
    for ns, ranges in zip(stamps, r.data["ranges"], strict=True):
        flat = ranges.reshape(-1)
        hit = np.isfinite(flat)
        points = (dirs[hit] * flat[hit, None]).astype(np.float32)[None, :, :]
        out.append(cdr.point_cloud(ns, r.sensor.frame_id, points, dense=True))
    return out


def scan_points(r: Reading, j: int) -> np.ndarray:
    """(n, 3) returns of lidar sample j in the sensor frame (the plot's, the replay's)."""
    li = r.sensor.lidar
    assert li is not None
    flat = r.data["ranges"][j].reshape(-1).astype(np.float64)
    hit = np.isfinite(flat)
    out: np.ndarray = lidar_directions(li)[hit] * flat[hit, None]
    return out
