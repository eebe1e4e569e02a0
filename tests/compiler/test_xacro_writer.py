"""The xacro set: course file names and includes, and inertia macros that are physically right.

The macros are checked through real xacro output against Pinocchio's own
solid-body formulas (pinocchio.Inertia.FromBox/FromCylinder/FromSphere), an
independent implementation of the same textbook tensors.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from lxml import etree

from armcli.compiler.expand import expand_urdfs
from armcli.compiler.xacro_writer import xacro_files
from armcli.compiler.xmlfmt import fmt
from armcli.spec.load import load_spec, loads_spec
from tests.helpers import ROOT

INERTIA_RTOL = 1e-12  # the macros and Pinocchio compute the same closed forms in float64

SHAPES_SPEC = """
name: shapes
materials: {red: {rgba: [1, 0, 0, 1], gazebo: Gazebo/Red}}
arm:
  links:
    slab_link:
      geometry: {box: {size: [0.7, 0.3, 0.11]}}
      origin: {xyz: [0.1, -0.2, 0.3], rpy: [0.3, -0.2, 1.1]}
      material: red
      mass: 2.5
    rod_link:
      geometry: {cylinder: {radius: 0.035, length: 0.45}}
      origin: {xyz: [0, 0, 0.225]}
      mass: 0.8
    ball_link:
      geometry: {sphere: {radius: 0.07}}
      mass: 1.3
  joints:
    j1: {type: revolute, parent: slab_link, child: rod_link, axis: [0, 1, 0],
         limit: {lower: -1, upper: 1, effort: 5, velocity: 2}}
    j2: {type: fixed, parent: rod_link, child: ball_link, origin: {xyz: [0, 0, 0.45]}}
"""


def _inertials(urdf: bytes) -> dict[str, tuple[float, np.ndarray, str, str]]:
    root = etree.fromstring(urdf)
    out = {}
    for link in root.iter("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        i = inertial.find("inertia").attrib
        tensor = np.array(
            [
                [float(i["ixx"]), float(i["ixy"]), float(i["ixz"])],
                [float(i["ixy"]), float(i["iyy"]), float(i["iyz"])],
                [float(i["ixz"]), float(i["iyz"]), float(i["izz"])],
            ]
        )
        origin = inertial.find("origin").attrib
        mass = float(inertial.find("mass").attrib["value"])
        out[str(link.attrib["name"])] = (mass, tensor, str(origin["xyz"]), str(origin["rpy"]))
    return out


def test_macros_match_pinocchio_solid_bodies() -> None:
    spec = loads_spec(SHAPES_SPEC)
    urdf = expand_urdfs(spec)["standalone_arm.urdf"]
    got = _inertials(urdf)
    expected = {
        "slab_link": pin.Inertia.FromBox(2.5, 0.7, 0.3, 0.11),
        "rod_link": pin.Inertia.FromCylinder(0.8, 0.035, 0.45),
        "ball_link": pin.Inertia.FromSphere(1.3, 0.07),
    }
    for name, ref in expected.items():
        mass, tensor, _, _ = got[name]
        assert mass == ref.mass
        np.testing.assert_allclose(tensor, ref.inertia, rtol=INERTIA_RTOL, atol=0)
    # The inertial frame is the shape frame: same origin as the visual geometry.
    assert got["slab_link"][2:] == ("0.1 -0.2 0.3", "0.3 -0.2 1.1")


def test_default_robot_inertias_match_its_geometry(built_dir: Path) -> None:
    spec = load_spec(ROOT / "specs" / "my_robot.yaml")
    got = _inertials((built_dir / "my_robot.urdf").read_bytes())
    for name, link in spec.all_links().items():
        if link.geometry is None:
            assert name not in got
            continue
        g = link.geometry
        if g.box is not None:
            ref = pin.Inertia.FromBox(link.mass, *g.box.size)
        elif g.cylinder is not None:
            ref = pin.Inertia.FromCylinder(link.mass, g.cylinder.radius, g.cylinder.length)
        else:
            assert g.sphere is not None
            ref = pin.Inertia.FromSphere(link.mass, g.sphere.radius)
        np.testing.assert_allclose(got[name][1], ref.inertia, rtol=INERTIA_RTOL, atol=0)


def test_course_file_set_and_includes() -> None:
    spec = loads_spec(SHAPES_SPEC)
    assert sorted(xacro_files(spec)) == [
        "arm.xacro",
        "arm_gazebo.xacro",
        "common_properties.xacro",
        "standalone_arm.urdf.xacro",
    ]
    default = load_spec(ROOT / "specs" / "my_robot.yaml")
    files = xacro_files(default)
    assert sorted(files) == [
        "arm.xacro",
        "arm_gazebo.xacro",
        "common_properties.xacro",
        "mobile_base.xacro",
        "mobile_base_gazebo.xacro",
        "my_robot.urdf.xacro",
        "standalone_arm.urdf.xacro",
    ]
    ns = {"xacro": "http://www.ros.org/wiki/xacro"}
    top = etree.fromstring(files["my_robot.urdf.xacro"])
    includes = [e.get("filename") for e in top.findall("xacro:include", ns)]
    assert includes == [
        "common_properties.xacro",
        "mobile_base.xacro",
        "mobile_base_gazebo.xacro",
        "arm.xacro",
        "arm_gazebo.xacro",
    ]
    mount = top.find("joint")
    assert mount is not None and mount.get("name") == "mobile_base_arm_joint"
    assert mount.get("type") == "fixed"
    assert mount.find("origin").get("xyz") == "0.15 0 0.2"
    standalone = etree.fromstring(files["standalone_arm.urdf.xacro"])
    assert [e.get("filename") for e in standalone.findall("xacro:include", ns)] == [
        "common_properties.xacro",
        "arm.xacro",
        "arm_gazebo.xacro",
    ]


def test_gazebo_plugins_carry_the_seed_rates() -> None:
    default = load_spec(ROOT / "specs" / "my_robot.yaml")
    arm_gz = etree.fromstring(xacro_files(default)["arm_gazebo.xacro"])
    plugins = {p.get("filename"): p for p in arm_gz.iter("plugin")}
    jsp = plugins["libgazebo_ros_joint_state_publisher.so"]
    assert jsp.findtext("update_rate") == "10"
    assert [e.text for e in jsp.findall("joint_name")] == [
        "arm_base_forearm_joint",
        "forearm_hand_joint",
    ]
    assert plugins["libgazebo_ros_joint_pose_trajectory.so"].findtext("update_rate") == "2"
    base_gz = etree.fromstring(xacro_files(default)["mobile_base_gazebo.xacro"])
    dd = next(base_gz.iter("plugin"))
    assert dd.findtext("wheel_separation") == "0.45"
    assert dd.findtext("wheel_diameter") == "0.2"
    caster = base_gz.find("gazebo[@reference='caster_wheel_link']")
    assert caster is not None and caster.find("mu1").get("value") == "0.1"


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (0.0, "0"),
        (-0.0, "0"),
        (100.0, "100"),
        (0.1, "0.1"),
        (1.5707963267948966, "1.5707963267948966"),
    ],
)
def test_float_format_round_trips(value: float, text: str) -> None:
    assert fmt(value) == text
    assert float(fmt(value)) == value
