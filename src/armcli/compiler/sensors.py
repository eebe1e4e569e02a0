"""Spec sensors -> Gazebo classic sensors, and Gazebo Harmonic sensors with their bridge.

Classic (`build`'s URDF, the humble-classic target): camera and depth camera through
gazebo_ros_camera (TOPIC/image_raw, TOPIC/camera_info; TOPIC/depth/image_raw and
TOPIC/points), a lidar through gazebo_ros_ray_sensor (LaserScan on TOPIC for one ring,
PointCloud2 for several), an IMU through gazebo_ros_imu_sensor (TOPIC).
Harmonic (`--target jazzy`): the same sensors as gz-sim publishes them (`<topic>`,
`<gz_frame_id>`), the Sensors/Imu systems they need, and one bridge entry per ROS topic,
so both targets publish the same ROS topics.
"""

from __future__ import annotations

from typing import Any

from lxml import etree

from armcli.compiler.xmlfmt import fmt, sub, vec
from armcli.spec.model import Sensor

CLASSIC_TYPES = {"camera": "camera", "depth_camera": "depth", "lidar": "ray", "imu": "imu"}
HARMONIC_TYPES = {
    "camera": "camera",
    "depth_camera": "depth_camera",
    "lidar": "gpu_lidar",
    "imu": "imu",
}
SENSORS_SYSTEM = ("gz-sim-sensors-system", "gz::sim::systems::Sensors")
IMU_SYSTEM = ("gz-sim-imu-system", "gz::sim::systems::Imu")
RENDER_ENGINE = "ogre2"


def _text(parent: etree._Element, tag: str, text: str) -> etree._Element:
    el = etree.SubElement(parent, tag)
    el.text = text
    return el


def _noise(parent: etree._Element, mean: float, stddev: float, attr: bool = False) -> None:
    n = sub(parent, "noise", **({"type": "gaussian"} if attr else {}))
    if not attr:
        _text(n, "type", "gaussian")
    _text(n, "mean", fmt(mean))
    _text(n, "stddev", fmt(stddev))


def _common(el: etree._Element, s: Sensor) -> None:
    _text(el, "pose", vec((*s.origin.xyz, *s.origin.rpy)))
    _text(el, "always_on", "true")
    _text(el, "update_rate", fmt(s.rate))
    _text(el, "visualize", "true" if s.visualize else "false")


def _camera(el: etree._Element, name: str, s: Sensor, info_topic: str | None) -> None:
    c = s.camera
    assert c is not None
    cam = sub(el, "camera", name=name)
    if info_topic is not None:
        _text(cam, "camera_info_topic", info_topic)
    _text(cam, "horizontal_fov", fmt(c.horizontal_fov))
    image = sub(cam, "image")
    _text(image, "width", str(c.width))
    _text(image, "height", str(c.height))
    _text(image, "format", c.format)
    clip = sub(cam, "clip")
    _text(clip, "near", fmt(c.near))
    _text(clip, "far", fmt(c.far))
    if s.noise is not None:
        _noise(cam, s.noise.mean, s.noise.stddev)


def _rays(el: etree._Element, s: Sensor, tag: str) -> None:
    li = s.lidar
    assert li is not None
    ray = sub(el, tag)
    scan = sub(ray, "scan")
    h = sub(scan, "horizontal")
    horizontal = (
        ("samples", str(li.samples)),
        ("resolution", "1"),
        ("min_angle", fmt(li.min_angle)),
        ("max_angle", fmt(li.max_angle)),
    )
    for key, value in horizontal:
        _text(h, key, value)
    if li.is_3d:
        v = sub(scan, "vertical")
        for key, value in (
            ("samples", str(li.vertical_samples)),
            ("resolution", "1"),
            ("min_angle", fmt(li.vertical_min_angle)),
            ("max_angle", fmt(li.vertical_max_angle)),
        ):
            _text(v, key, value)
    rng = sub(ray, "range")
    _text(rng, "min", fmt(li.range_min))
    _text(rng, "max", fmt(li.range_max))
    _text(rng, "resolution", fmt(li.resolution))
    if s.noise is not None:
        _noise(ray, s.noise.mean, s.noise.stddev)


def _imu(el: etree._Element, s: Sensor) -> None:
    imu = sub(el, "imu")
    gyro = s.imu.angular_velocity_stddev if s.imu is not None else 0.0
    acc = s.imu.linear_acceleration_stddev if s.imu is not None else 0.0
    for group, stddev in (("angular_velocity", gyro), ("linear_acceleration", acc)):
        g = sub(imu, group)
        for axis in "xyz":
            _noise(sub(g, axis), 0.0, stddev, attr=True)


def _ros(plugin: etree._Element, remaps: list[tuple[str, str]]) -> None:
    ros = sub(plugin, "ros")
    for src, dst in remaps:
        _text(ros, "remapping", f"{src}:={dst}")


def classic_sensor(name: str, s: Sensor) -> etree._Element:
    """`<gazebo reference=LINK><sensor>` with its gazebo_ros plugin (Gazebo classic)."""
    gz = etree.Element("gazebo", reference=s.link)
    el = sub(gz, "sensor", name=name, type=CLASSIC_TYPES[s.type])
    _common(el, s)
    t = s.topic
    if s.type in ("camera", "depth_camera"):
        _camera(el, name, s, None)
        plugin = sub(el, "plugin", name=f"{name}_plugin", filename="libgazebo_ros_camera.so")
        remaps = [("~/image_raw", f"{t}/image_raw"), ("~/camera_info", f"{t}/camera_info")]
        if s.type == "depth_camera":
            remaps += [("~/depth/image_raw", f"{t}/depth/image_raw"), ("~/points", f"{t}/points")]
        _ros(plugin, remaps)
        _text(plugin, "camera_name", name)
    elif s.type == "lidar":
        assert s.lidar is not None
        _rays(el, s, "ray")
        plugin = sub(el, "plugin", name=f"{name}_plugin", filename="libgazebo_ros_ray_sensor.so")
        _ros(plugin, [("~/out", t)])
        kind = "PointCloud2" if s.lidar.is_3d else "LaserScan"
        _text(plugin, "output_type", f"sensor_msgs/{kind}")
    else:
        _imu(el, s)
        plugin = sub(el, "plugin", name=f"{name}_plugin", filename="libgazebo_ros_imu_sensor.so")
        _ros(plugin, [("~/out", t)])
        _text(plugin, "initial_orientation_as_reference", "false")
    _text(plugin, "frame_name", s.frame_id)
    return gz


def harmonic_topic(s: Sensor) -> str:
    """The gz topic a Harmonic sensor publishes its main data on."""
    if s.type == "camera":
        return f"{s.topic}/image_raw"
    if s.type == "depth_camera":
        return f"{s.topic}/depth/image_raw"
    return s.topic


def harmonic_sensor(name: str, s: Sensor) -> etree._Element:
    """`<gazebo reference=LINK><sensor>` as gz-sim (Gazebo Harmonic) reads it."""
    gz = etree.Element("gazebo", reference=s.link)
    el = sub(gz, "sensor", name=name, type=HARMONIC_TYPES[s.type])
    _common(el, s)
    _text(el, "topic", harmonic_topic(s))
    _text(el, "gz_frame_id", s.frame_id)
    if s.type in ("camera", "depth_camera"):
        _camera(el, name, s, f"{s.topic}/camera_info")
    elif s.type == "lidar":
        _rays(el, s, "lidar")
    else:
        _imu(el, s)
    return gz


def _entry(ros: str, gz: str, ros_type: str, gz_type: str) -> dict[str, Any]:
    return {
        "ros_topic_name": ros,
        "gz_topic_name": gz,
        "ros_type_name": ros_type,
        "gz_type_name": gz_type,
        "direction": "GZ_TO_ROS",
    }


def bridge_entries(s: Sensor) -> list[dict[str, Any]]:
    """ros_gz_bridge entries that put a Harmonic sensor on the classic target's ROS topics."""
    t, main = s.topic, harmonic_topic(s)
    image, info = (
        ("sensor_msgs/msg/Image", "gz.msgs.Image"),
        ("sensor_msgs/msg/CameraInfo", "gz.msgs.CameraInfo"),
    )
    cloud = ("sensor_msgs/msg/PointCloud2", "gz.msgs.PointCloudPacked")
    if s.type == "camera":
        return [_entry(main, main, *image), _entry(f"{t}/camera_info", f"{t}/camera_info", *info)]
    if s.type == "depth_camera":
        return [
            _entry(main, main, *image),
            _entry(f"{t}/camera_info", f"{t}/camera_info", *info),
            _entry(f"{t}/points", f"{main}/points", *cloud),
        ]
    if s.type == "lidar":
        assert s.lidar is not None
        if s.lidar.is_3d:
            return [_entry(t, f"{t}/points", *cloud)]
        return [_entry(t, t, "sensor_msgs/msg/LaserScan", "gz.msgs.LaserScan")]
    return [_entry(t, t, "sensor_msgs/msg/Imu", "gz.msgs.IMU")]


def harmonic_systems(sensors: list[Sensor]) -> list[etree._Element]:
    """The gz-sim systems the sensors need (rendering sensors, IMUs), as `<gazebo><plugin>`."""
    out = []
    if any(s.type != "imu" for s in sensors):
        gz = etree.Element("gazebo")
        p = sub(gz, "plugin", filename=SENSORS_SYSTEM[0], name=SENSORS_SYSTEM[1])
        _text(p, "render_engine", RENDER_ENGINE)
        out.append(gz)
    if any(s.type == "imu" for s in sensors):
        gz = etree.Element("gazebo")
        sub(gz, "plugin", filename=IMU_SYSTEM[0], name=IMU_SYSTEM[1])
        out.append(gz)
    return out
