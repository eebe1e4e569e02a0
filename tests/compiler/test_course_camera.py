"""The course's camera.xacro (its earlier section) written as a typed spec: the same camera
link, optical frame and joints, and a typed camera sensor that Gazebo runs as the course's
(same name, link, rate, frame, plugin); checked against the student fixture's expansion,
the closed-form box inertia and SDFormat."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path
from typing import Any, cast

import pytest
import yaml
from lxml import etree

from armcli.compiler.expand import expand_urdfs
from armcli.spec.load import loads_spec
from armcli.urdf.source import expand_xacro
from tests.helpers import DEFAULT_SPEC, FIXTURES

STUDENT = FIXTURES / "import" / "course_student" / "urdf" / "my_robot.urdf.xacro"
CAMERA: dict[str, Any] = {
    "links": {
        "camera_link": {
            "geometry": {"box": {"size": [0.01, 0.1, 0.05]}},
            "material": "camera_grey",
            "mass": 0.1,
        },
        "camera_link_optical": {},
    },
    "joints": {
        "base_camera_joint": {
            "type": "fixed",
            "parent": "base_link",
            "child": "camera_link",
            "origin": {"xyz": ["(0.6 + 0.01) / 2", 0, "0.2 / 2"]},
        },
        "camera_optical_joint": {
            "type": "fixed",
            "parent": "camera_link",
            "child": "camera_link_optical",
            "origin": {"rpy": ["-pi/2", 0, "-pi/2"]},
        },
    },
}
# gazebo_ros_camera's topics for a sensor named camera_sensor; Gazebo's default image.
SENSOR = {
    "type": "camera",
    "link": "camera_link",
    "rate": 10,
    "topic": "camera_sensor",
    "frame": "camera_link_optical",
    "visualize": True,
    "camera": {"width": 320, "height": 240, "horizontal_fov": 1.047, "near": 0.1},
}


def _spec_text() -> str:
    data = yaml.safe_load(DEFAULT_SPEC.read_text())
    data["materials"]["camera_grey"] = {"rgba": [0.5, 0.5, 0.5, 1.0], "gazebo": "Gazebo/Red"}
    data["mobile_base"]["links"].update(CAMERA["links"])
    data["mobile_base"]["joints"].update(CAMERA["joints"])
    data["sensors"] = {"camera_sensor": SENSOR}
    return yaml.safe_dump(data, sort_keys=False)


@pytest.fixture(scope="module")
def built() -> etree._Element:
    spec = loads_spec(_spec_text(), "course_camera.yaml")
    return etree.fromstring(expand_urdfs(spec)["my_robot.urdf"])


@pytest.fixture(scope="module")
def course() -> etree._Element:
    xml, _ = expand_xacro(STUDENT)
    return etree.fromstring(xml)


def _floats(el: etree._Element | None, attr: str) -> list[float]:
    assert el is not None
    return [float(x) for x in str(el.get(attr, "0 0 0")).split()]


def _camera_sensor(root: etree._Element) -> etree._Element:
    (sensor,) = cast("list[etree._Element]", root.xpath("gazebo[@reference='camera_link']/sensor"))
    return sensor


def test_links_and_joints_are_the_courses(built: etree._Element, course: etree._Element) -> None:
    for name in ("base_camera_joint", "camera_optical_joint"):
        ours, theirs = built.find(f"joint[@name='{name}']"), course.find(f"joint[@name='{name}']")
        assert ours is not None and theirs is not None
        assert ours.get("type") == theirs.get("type") == "fixed"
        for end in ("parent", "child"):
            assert ours.find(end).get("link") == theirs.find(end).get("link")
        for attr in ("xyz", "rpy"):
            assert _floats(ours.find("origin"), attr) == pytest.approx(
                _floats(theirs.find("origin"), attr), abs=1e-15
            )
    for tag in ("visual", "collision"):
        size = built.find(f"link[@name='camera_link']/{tag}/geometry/box")
        assert _floats(size, "size") == _floats(
            course.find(f"link[@name='camera_link']/{tag}/geometry/box"), "size"
        )
    assert built.find("link[@name='camera_link_optical']") is not None


def test_inertia_is_the_solid_box(built: etree._Element) -> None:
    """m/12 (b² + c²) about each axis: the course's box_inertia macro, unpermuted."""
    inertia = built.find("link[@name='camera_link']/inertial/inertia")
    assert inertia is not None
    m, (lx, ly, lz) = 0.1, (0.01, 0.1, 0.05)
    expected = {"ixx": m / 12 * (ly**2 + lz**2), "iyy": m / 12 * (lx**2 + lz**2),
                "izz": m / 12 * (lx**2 + ly**2)}  # fmt: skip
    for key, value in expected.items():
        assert float(str(inertia.get(key))) == pytest.approx(value, rel=1e-12)


def test_sensor_is_the_courses_camera(built: etree._Element, course: etree._Element) -> None:
    ours, theirs = _camera_sensor(built), _camera_sensor(course)
    assert (ours.get("name"), ours.get("type")) == (theirs.get("name"), theirs.get("type"))
    for tag in ("update_rate", "visualize"):
        assert yaml.safe_load(str(ours.findtext(tag))) == yaml.safe_load(str(theirs.findtext(tag)))
    for tag in ("plugin/frame_name",):
        assert ours.findtext(tag) == theirs.findtext(tag) == "camera_link_optical"
    assert ours.find("plugin").get("filename") == theirs.find("plugin").get("filename")
    # the topics gazebo_ros_camera gives the course's sensor: <camera_name>/image_raw, ...
    remaps = [r.text for r in ours.iterfind("plugin/ros/remapping")]
    assert remaps == ["~/image_raw:=camera_sensor/image_raw",
                      "~/camera_info:=camera_sensor/camera_info"]  # fmt: skip
    (material,) = cast("list[str]", built.xpath("gazebo[@reference='camera_link']/material/text()"))
    assert material == "Gazebo/Red"


def test_sdformat_reads_both_the_same(
    built: etree._Element, course: etree._Element, tmp_path: Path
) -> None:
    if shutil.which("ign") is None:
        pytest.skip("ign not installed (libsdformat-dev + ignition-tools; make sysdeps)")
    sensors = []
    for name, root in (("ours", built), ("course", course)):
        path = tmp_path / f"{name}.urdf"
        path.write_bytes(etree.tostring(root))
        check = subprocess.run(["ign", "sdf", "-k", str(path)], capture_output=True, text=True)
        assert "Valid" in check.stdout, check.stdout + check.stderr
        sdf = subprocess.run(["ign", "sdf", "-p", str(path)], capture_output=True, text=True)
        (sensor,) = etree.fromstring(sdf.stdout.encode()).iter("sensor")
        sensors.append(sensor)
    ours, theirs = sensors
    assert ours.getparent().get("name") == theirs.getparent().get("name") == "base_footprint"
    assert _floats_text(ours.findtext("pose")) == pytest.approx(
        _floats_text(theirs.findtext("pose"))
    )


def _floats_text(text: str | None) -> list[float]:
    return [float(x) for x in str(text).split()]
