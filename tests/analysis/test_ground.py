"""Ground contacts from collision geometry: wheels, a caster ball, box feet, mesh wheels."""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.analysis.ground import Ground, find_ground, has_wheels, mesh_loader
from armcli.compiler.expand import expand_urdfs
from armcli.robot.model import Robot
from armcli.spec.load import load_spec
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.read import parse_urdf
from tests.helpers import DEFAULT_SPEC

TOL = 1e-9  # [m]
MESH_TOL = 1e-3  # [m] a 64-sided mesh wheel's tread against the round one

WHEELED = """<robot name="r">
  <link name="base"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.6 0.4 0.2"/>
  </geometry></collision></link>
  {wheels}
  <link name="skid"><collision><origin xyz="0.25 0 0.1"/><geometry><box size="0.04 0.3 0.2"/>
  </geometry></collision></link>
  <joint name="skid_joint" type="fixed"><parent link="base"/><child link="skid"/></joint>
</robot>"""
WHEEL = """<link name="{n}"><collision><origin rpy="1.5707963 0 0"/><geometry>{g}</geometry>
  </collision></link><joint name="{n}_joint" type="continuous"><parent link="base"/>
  <child link="{n}"/><origin xyz="-0.2 {y} 0.1"/><axis xyz="0 1 0"/></joint>"""


def ground_of(xml: str, tmp: Path | None = None) -> Ground | None:
    urdf = parse_urdf(xml.encode(), str((tmp or Path("/nonexistent")) / "r.urdf"))
    robot = Robot.load(urdf, floating=True, strict=False)
    missing: list[str] = []
    return find_ground(urdf, robot, mesh=mesh_loader(urdf, MeshSearch(), missing))


def test_course_robot_touches_on_its_wheels_and_caster() -> None:
    spec = load_spec(DEFAULT_SPEC)
    urdf = parse_urdf(expand_urdfs(spec)["my_robot.urdf"], "my_robot.urdf")
    g = find_ground(urdf, Robot.load(urdf, floating=True, strict=False))
    assert g is not None and has_wheels(g)
    assert g.height == pytest.approx(0.0, abs=TOL)
    got = {c.link: (c.rolling, c.points) for c in g.contacts}
    # wheels (radius 0.1 on axles at z 0.1): one point below the axle; caster ball: its bottom
    expected: dict[str, object] = {
        "base_right_wheel_link": (True, ((-0.15, -0.225, pytest.approx(0.0, abs=TOL)),)),
        "base_left_wheel_link": (True, ((-0.15, 0.225, pytest.approx(0.0, abs=TOL)),)),
        "caster_wheel_link": (False, ((0.2, 0.0, pytest.approx(0.0, abs=TOL)),)),
    }
    assert got == expected


def test_a_skid_touches_at_its_bottom_corners() -> None:
    cyl = '<cylinder radius="0.1" length="0.05"/>'
    wheels = WHEEL.format(n="wl", y=0.25, g=cyl) + WHEEL.format(n="wr", y=-0.25, g=cyl)
    g = ground_of(WHEELED.format(wheels=wheels))
    skid = next(c for c in g.contacts if c.link == "skid")
    assert not skid.rolling
    assert sorted((round(x, 9), round(y, 9)) for x, y, _ in skid.points) == [
        (0.23, -0.15), (0.23, 0.15), (0.27, -0.15), (0.27, 0.15)
    ]  # fmt: skip
    assert "base" not in {c.link for c in g.contacts}  # its bottom is 0.15 m up


def test_mesh_wheels_touch_below_their_axles(tmp_path: Path) -> None:
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.cylinder(radius=0.1, height=0.05, sections=64).export(tmp_path / "w.stl")
    mesh = '<mesh filename="w.stl"/>'
    wheels = WHEEL.format(n="wl", y=0.25, g=mesh) + WHEEL.format(n="wr", y=-0.25, g=mesh)
    g = ground_of(WHEELED.format(wheels=wheels), tmp_path)
    for c in g.contacts:
        if c.rolling:
            ((x, y, z),) = c.points
            assert (x, abs(y), z) == pytest.approx((-0.2, 0.25, 0.0), abs=MESH_TOL)
    assert {c.link for c in g.contacts} == {"wl", "wr", "skid"}


def test_an_arm_on_a_table_has_no_wheels() -> None:
    xml = """<robot name="arm"><link name="base"><collision><origin xyz="0 0 0.05"/>
      <geometry><cylinder radius="0.1" length="0.1"/></geometry></collision></link>
      <link name="l1"><collision><origin xyz="0 0 0.2"/><geometry><box size="0.05 0.05 0.3"/>
      </geometry></collision></link><joint name="j1" type="revolute"><parent link="base"/>
      <child link="l1"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
      <limit lower="-3" upper="3" effort="10" velocity="1"/></joint></robot>"""
    g = ground_of(xml)
    assert g is not None and not has_wheels(g)
    (base,) = g.contacts  # the upright cylinder's bottom rim
    assert base.link == "base" and len(base.points) == 32


def test_a_wrist_hanging_below_a_bolted_arm_is_no_wheel() -> None:
    """example-robot-data's UR5 at zero: its wrist links hang below the base's bottom and
    turn about horizontal axes, behind the arm's joints; the arm is still bolted down."""
    xml = """<robot name="arm"><link name="base"><collision><origin xyz="0 0 0.05"/>
      <geometry><cylinder radius="0.1" length="0.1"/></geometry></collision></link>
      <link name="upper"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.05 0.05"/>
      </geometry></collision></link><joint name="shoulder" type="revolute"><parent link="base"/>
      <child link="upper"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
      <limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
      <link name="wrist"><collision><origin rpy="1.5707963 0 0"/><geometry>
      <cylinder radius="0.05" length="0.05"/></geometry></collision></link>
      <joint name="wrist_joint" type="revolute"><parent link="upper"/><child link="wrist"/>
      <origin xyz="0.4 0 -0.06"/><axis xyz="0 1 0"/>
      <limit lower="-3" upper="3" effort="10" velocity="1"/></joint></robot>"""
    g = ground_of(xml)
    assert g is not None and {c.link for c in g.contacts} == {"wrist"}  # lowest: 1 cm below
    assert not has_wheels(g)
