"""The round-trip comparison sees every change of meaning and nothing else."""

from __future__ import annotations

import pytest
from lxml import etree

from armcli.importer.compare import compare_urdf

BASE = """<robot name="r">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="a">
    <visual name="v"><origin xyz="0 0 0.1" rpy="0 0 0"/>
      <geometry><mesh filename="package://p/m.stl" scale="1 1 1"/></geometry>
      <material name="grey"/></visual>
    <collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision>
    <inertial><origin xyz="0 0 0.1"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
  </link>
  <link name="b"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 0.2" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="2"/>
    <dynamics damping="0.1" friction="0.05"/>
  </joint>
  <gazebo reference="a"><mu1>0.5</mu1></gazebo>
  <transmission name="t"><type>x</type></transmission>
</robot>"""


def _diff(a: str, b: str) -> list[str]:
    return [str(d) for d in compare_urdf(etree.fromstring(a), etree.fromstring(b))]


def test_same_meaning_different_text_is_equal() -> None:
    other = (
        BASE.replace('<origin xyz="0 0 0.2" rpy="0 0 0"/>', '<origin xyz="0 0 2e-1"/>')
        .replace('scale="1 1 1"', "")
        .replace("<mu1>0.5</mu1>", '<mu1 value="0.50"/>')
        .replace(
            '<dynamics damping="0.1" friction="0.05"/>',
            '<dynamics friction="0.05" damping="0.1"></dynamics>',
        )
    )
    assert _diff(BASE, other) == []


@pytest.mark.parametrize(
    ("old", "new", "where"),
    [
        ('name="r"', 'name="s"', "robot name"),
        ('<mass value="2"/>', '<mass value="2.000001"/>', "link a inertial"),
        ('ixy="0"', 'ixy="1e-9"', "link a inertial"),
        ('<box size="0.1 0.2 0.3"/>', '<box size="0.1 0.3 0.2"/>', "link a collision[0] geometry"),
        ("package://p/m.stl", "package://q/m.stl", "link a visual[0] geometry"),
        ('<visual name="v">', "<visual>", "link a visual[0] name"),
        ('<color rgba="0.5 0.5 0.5 1"/>', '<color rgba="0.5 0.5 0.6 1"/>', "material 'grey'"),
        ('<axis xyz="0 1 0"/>', "", "joint j axis"),
        ('effort="10"', 'effort="11"', "joint j limit"),
        ('damping="0.1"', 'damping="0.2"', "joint j dynamics"),
        ("</joint>", '<mimic joint="j"/></joint>', "joint j mimic"),
        ('xyz="0 0 0.2" rpy="0 0 0"/>', 'xyz="0 0 0.2" rpy="0 0 1e-12"/>', "joint j origin"),
        ("<mu1>0.5</mu1>", "<mu1>0.6</mu1>", "gazebo a"),
        ("<type>x</type>", "<type>y</type>", "element"),
        ('<link name="b"/>', '<link name="b"><foo/></link>', "link b other"),
    ],
)  # fmt: skip
def test_every_change_of_meaning_is_found(old: str, new: str, where: str) -> None:
    assert old in BASE
    diffs = _diff(BASE, BASE.replace(old, new, 1))
    assert any(d.startswith(where) for d in diffs), diffs


def test_inertials_compare_to_1e12_relative() -> None:
    close = BASE.replace('iyy="0.02"', f'iyy="{0.02 * (1 + 5e-13)!r}"')
    far = BASE.replace('iyy="0.02"', f'iyy="{0.02 * (1 + 5e-11)!r}"')
    assert _diff(BASE, close) == []
    assert _diff(BASE, far) != []
