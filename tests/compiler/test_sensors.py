"""Sensors compiled for Gazebo classic (in the built URDF) and Gazebo Harmonic (Jazzy target),
with SDFormat, Gazebo's own URDF parser, as the oracle where it is installed."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
import yaml
from lxml import etree

from armcli.compiler.expand import build
from armcli.errors import SpecError
from armcli.ros import jazzy
from armcli.spec.load import load_spec, loads_spec
from tests.compiler.test_acceptance import SPEC, write_meshes

TOPICS = {  # the ROS topics each sensor publishes on both targets
    "wrist_camera": {"wrist_camera/image_raw", "wrist_camera/camera_info"},
    "wrist_depth": {"wrist_depth/image_raw", "wrist_depth/camera_info",
                    "wrist_depth/depth/image_raw", "wrist_depth/points"},
    "base_scan": {"scan"},
    "base_cloud": {"points"},
    "base_imu": {"imu"},
}  # fmt: skip


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    project = tmp_path_factory.mktemp("sensors")
    # the fixture's stiff gains hold only with ros2_control updating faster than 5.5 kHz
    # (ros-controller-unstable, which tests/test_specs_smoke.py expects of it); the Jazzy
    # target refuses them at the default 100 Hz, so this copy updates at 10 kHz
    text = SPEC.read_text().replace("\ncontrol:\n", "\ncontrol:\n  controller_update_rate: 10000\n")
    assert "controller_update_rate: 10000" in text
    (project / "armcli.yaml").write_text(text)
    write_meshes(project)
    build(project / "armcli.yaml", project / "urdf")
    return project


def _ign(*args: str) -> subprocess.CompletedProcess[str]:
    if shutil.which("ign") is None:
        pytest.skip("ign not installed (libsdformat-dev + ignition-tools; make sysdeps)")
    return subprocess.run(["ign", "sdf", *args], capture_output=True, text=True, check=False)


def _classic_topics(sensor: etree._Element) -> set[str]:
    remaps = [r.text.split(":=")[1] for r in sensor.iter("remapping")]
    return set(remaps)


def test_classic_sensors_are_in_the_built_urdf(project: Path) -> None:
    root = etree.parse(str(project / "urdf" / "standalone_arm.urdf")).getroot()
    sensors = {s.get("name"): s for s in root.iter("sensor")}
    assert set(sensors) == set(TOPICS)
    for name, topics in TOPICS.items():
        got = _classic_topics(sensors[name])
        assert got <= topics and ("image_raw" in str(got) or got == topics), (name, got)
    cam = sensors["wrist_camera"]
    assert cam.getparent().get("reference") == "wrist_3_link"
    assert cam.findtext("camera/image/width") == "640"
    assert cam.findtext("update_rate") == "30"
    assert cam.find("plugin").get("filename") == "libgazebo_ros_camera.so"
    assert sensors["base_scan"].findtext("plugin/output_type") == "sensor_msgs/LaserScan"
    assert sensors["base_cloud"].findtext("plugin/output_type") == "sensor_msgs/PointCloud2"
    assert sensors["base_cloud"].findtext("ray/scan/vertical/samples") == "16"
    gyro = sensors["base_imu"].find("imu/angular_velocity/x/noise/stddev")
    assert gyro is not None and gyro.text == "0.0002"


def test_sdformat_turns_every_classic_sensor_into_an_sdf_sensor(project: Path) -> None:
    urdf = project / "urdf" / "standalone_arm.urdf"
    assert "Valid" in _ign("-k", str(urdf)).stdout
    sdf = etree.fromstring(_ign("-p", str(urdf)).stdout.encode())
    types = {s.get("name"): s.get("type") for s in sdf.iter("sensor")}
    assert types == {
        "wrist_camera": "camera", "wrist_depth": "depth", "base_scan": "ray",
        "base_cloud": "ray", "base_imu": "imu",
    }  # fmt: skip


def test_harmonic_sensors_and_the_bridge_give_the_same_ros_topics(project: Path) -> None:
    spec = load_spec(project / "armcli.yaml")
    bridged = {e["ros_topic_name"] for e in jazzy.bridge(spec)}
    # gz-sim's depth camera has no colour image: the classic plugin's extra image_raw
    assert bridged == {"clock"} | {t for ts in TOPICS.values() for t in ts} - {
        "wrist_depth/image_raw"
    }
    top = etree.fromstring(jazzy.top_xacro(spec, "rich_arm_bringup", whole=False, header="x"))
    sensors = {s.get("name"): s for s in top.iter("sensor")}
    assert {n: s.get("type") for n, s in sensors.items()} == {
        "wrist_camera": "camera", "wrist_depth": "depth_camera", "base_scan": "gpu_lidar",
        "base_cloud": "gpu_lidar", "base_imu": "imu",
    }  # fmt: skip
    gz_topics = {e["gz_topic_name"] for e in jazzy.bridge(spec)}
    for s in sensors.values():  # each sensor's gz topic (a 3-D lidar's cloud: TOPIC/points)
        assert {s.findtext("topic"), f"{s.findtext('topic')}/points"} & gz_topics
    assert sensors["wrist_camera"].findtext("gz_frame_id") == "wrist_3_link"
    plugins = {p.get("filename") for p in top.iter("plugin")}
    assert {"gz-sim-sensors-system", "gz-sim-imu-system"} <= plugins


def test_jazzy_bringup_writes_the_bridge_config(project: Path) -> None:
    from armcli.ros.packages import ros_packages

    spec = load_spec(project / "armcli.yaml")
    files = ros_packages(spec, samples=50, target="jazzy").files
    entries = yaml.safe_load(files["rich_arm_bringup/config/rich_arm_bridge.yaml"])
    assert entries[0]["ros_topic_name"] == "clock"
    assert {e["direction"] for e in entries} == {"GZ_TO_ROS"}
    launch = files["rich_arm_bringup/launch/rich_arm_gz.launch.py"].decode()
    assert 'BRIDGE = "rich_arm_bridge.yaml"' in launch


@pytest.mark.parametrize(
    ("sensor", "fragment"),
    [
        ("{type: camera, link: base_link, rate: 10, topic: cam}", "a camera needs `camera`"),
        ("{type: imu, link: base_link, rate: 10, topic: imu, camera: {width: 1, height: 1, "
         "horizontal_fov: 1}}", "`camera` is for another sensor type"),
        ("{type: imu, link: nowhere, rate: 10, topic: imu}", "unknown link 'nowhere'"),
        ("{type: imu, link: base_link, rate: 0, topic: imu}", "greater than 0"),
        ("{type: lidar, link: base_link, rate: 5, topic: scan, lidar: {samples: 10, "
         "min_angle: 1, max_angle: -1, range_min: 0.1, range_max: 5}}", "max_angle must be"),
        ("{type: imu, link: base_link, rate: 10, topic: 'bad topic'}", "String should match"),
    ],
)  # fmt: skip
def test_sensor_mistakes(sensor: str, fragment: str) -> None:
    text = SPEC.read_text().split("\nsensors:")[0] + f"\nsensors:\n  s1: {sensor}\n"
    text = text.replace("meshes/", "/nonexistent/")  # never read: validation fails first
    with pytest.raises(SpecError) as info:
        loads_spec(text)
    assert any(fragment in ln for ln in info.value.lines()), info.value.lines()


def test_sdformat_accepts_the_harmonic_description(project: Path, tmp_path: Path) -> None:
    import xacro

    from armcli.ros.packages import ros_packages

    spec = load_spec(project / "armcli.yaml")
    files = ros_packages(spec, samples=50, target="jazzy").files
    for rel, data in files.items():
        if rel.startswith("rich_arm_description/urdf/"):
            (tmp_path / Path(rel).name).write_bytes(data)
    mappings = {"controllers_file": str(tmp_path / "c.yaml"), "use_mock_hardware": "false"}
    doc = xacro.process_file(str(tmp_path / "standalone_arm_gz.urdf.xacro"), mappings=mappings)
    (tmp_path / "gz.urdf").write_text(doc.toprettyxml())
    assert "Valid" in _ign("-k", str(tmp_path / "gz.urdf")).stdout
