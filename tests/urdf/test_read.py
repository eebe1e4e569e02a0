"""Strict URDF reading: hostile XML refused, numbers checked, line numbers kept."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from armcli.errors import InputError, XacroRefusedError
from armcli.urdf.read import MAX_URDF_BYTES, MAX_URDF_DEPTH, parse_urdf, read_urdf

ARM = b"""<?xml version="1.0"?>
<robot name="r">
  <link name="a"/>
  <link name="b">
    <inertial>
      <mass value="%(mass)s"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>
    </inertial>
  </link>
  <joint name="j" type="revolute">
    <parent link="a"/>
    <child link="b"/>
    <origin xyz="%(xyz)s"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def arm(mass: str = "1", xyz: str = "0 0 0") -> bytes:
    return ARM % {b"mass": mass.encode(), b"xyz": xyz.encode()}


def test_generated_robot_is_read_completely(root: Path) -> None:
    path = root / "urdf" / "my_robot.urdf"
    text = path.read_text()
    u = read_urdf(path)
    # Independent count: the element names as they appear in the text.
    assert {lk.name for lk in u.links} == set(re.findall(r'<link name="(\w+)"', text))
    assert {j.name for j in u.joints} == set(re.findall(r'<joint name="(\w+)"', text))
    assert u.problems == ()
    line = text.splitlines().index('  <link name="hand_link">') + 1
    assert u.link("hand_link").line == line


def test_line_numbers_and_values() -> None:
    u = parse_urdf(arm(), "x.urdf")
    b = u.link("b")
    assert b.inertial.mass == 1.0 and b.inertial.mass_line == 6
    assert u.joints[0].limit.upper == 1.0 and u.joints[0].limit.line == 14


@pytest.mark.parametrize(
    ("mass", "xyz", "kind"),
    [
        ("nan", "0 0 0", "non-finite"),
        ("abc", "0 0 0", "not-a-number"),
        ("1", "0 0", "length"),
        ("1e999", "0 0 0", "non-finite"),
    ],
)
def test_bad_numbers_are_recorded_with_their_line(mass: str, xyz: str, kind: str) -> None:
    u = parse_urdf(arm(mass, xyz), "x.urdf")
    assert [p.kind for p in u.problems] == [kind]
    assert u.problems[0].line == (6 if kind != "length" else 13)


BILLION_LAUGHS = b"""<?xml version="1.0"?>
<!DOCTYPE robot [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>
<robot name="&b;"><link name="x"/></robot>
"""
EXTERNAL_ENTITY = b"""<?xml version="1.0"?>
<!DOCTYPE r [<!ENTITY e SYSTEM "file:///etc/passwd">]>
<robot name="r"><link name="&e;"/></robot>
"""


@pytest.mark.parametrize("data", [BILLION_LAUGHS, EXTERNAL_ENTITY])
def test_doctype_and_entities_are_refused(data: bytes) -> None:
    with pytest.raises(InputError, match="DOCTYPE/entity") as exc:
        parse_urdf(data, "evil.urdf")
    assert exc.value.line == 2


def test_size_and_depth_caps() -> None:
    with pytest.raises(InputError, match="larger than"):
        parse_urdf(b" " * (MAX_URDF_BYTES + 1), "big.urdf")
    deep = b"<robot name='r'>" + b"<a>" * MAX_URDF_DEPTH + b"</a>" * MAX_URDF_DEPTH + b"</robot>"
    with pytest.raises(InputError, match="nested deeper"):
        parse_urdf(deep, "deep.urdf")


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"<robot name='r'><link name='a'></robot>", "not well-formed"),
        (b"<sdf version='1.6'/>", "root element is <sdf>"),
        (b"\x00\x01binary", "not well-formed"),
    ],
)
def test_not_urdf(data: bytes, message: str) -> None:
    with pytest.raises(InputError, match=message):
        parse_urdf(data, "x.urdf")


@pytest.mark.parametrize("ns", ["http://www.ros.org/wiki/xacro", "http://wiki.ros.org/xacro"])
def test_xacro_content_is_refused_whatever_the_suffix(ns: str) -> None:
    data = f"<robot name='r' xmlns:xacro='{ns}'><xacro:property name='p' value='1'/></robot>"
    with pytest.raises(XacroRefusedError, match="--trust-xacro"):
        parse_urdf(data.encode(), "x.urdf")


def test_unreadable_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="URDF file not found"):
        read_urdf(tmp_path / "missing.urdf")
    (tmp_path / "locked.urdf").write_text("<robot name='r'/>")
    (tmp_path / "locked.urdf").chmod(0)
    if os.geteuid() != 0:  # root reads mode-0 files
        with pytest.raises(InputError, match="cannot read URDF file: Permission denied"):
            read_urdf(tmp_path / "locked.urdf")
