"""Mimic joints are honoured wherever armcli poses a robot: check's samples and poses and
the collision matrix set a follower from its leader (q = multiplier * leader + offset)."""

from __future__ import annotations

import pytest

from armcli.robot.mimic import Mimic, follow, mimics
from armcli.urdf.read import parse_urdf

# Two fingers closing on each other along y: 0.04 m wide boxes whose centres start 0.1 m
# apart. Moved independently they touch when left + right > 0.06 m, which part of the
# range box reaches; coupled (right = 0.035 - left) they always stay 0.025 m apart.
GRIPPER = """<robot name="gripper">
  <link name="palm"><collision><origin xyz="0 0 -0.2"/><geometry><box size="0.01 0.01 0.01"/>
    </geometry></collision><inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  {finger_links}
  <joint name="left_joint" type="prismatic"><parent link="palm"/><child link="left"/>
    <origin xyz="0 0.05 0"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.035" effort="10" velocity="0.1"/></joint>
  <joint name="right_joint" type="prismatic"><parent link="palm"/><child link="right"/>
    <origin xyz="0 -0.05 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.035" effort="10" velocity="0.1"/>{mimic}</joint>
</robot>"""
FINGER = """<link name="{name}"><collision><geometry><box size="0.02 0.04 0.02"/></geometry>
  </collision><inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5"
  ixy="0" ixz="0" iyz="0"/></inertial></link>"""
COUPLED = '<mimic joint="left_joint" multiplier="-1" offset="0.035"/>'


def gripper(mimic: str) -> bytes:
    links = "".join(FINGER.format(name=n) for n in ("left", "right"))
    return GRIPPER.format(finger_links=links, mimic=mimic).encode()


def test_reader_keeps_multiplier_and_offset() -> None:
    doc = parse_urdf(gripper(COUPLED), "g.urdf")
    assert mimics(doc.joints) == [Mimic("right_joint", "left_joint", -1.0, 0.035)]
    bare = parse_urdf(gripper('<mimic joint="left_joint"/>'), "g.urdf")
    assert mimics(bare.joints) == [Mimic("right_joint", "left_joint", 1.0, 0.0)]


def test_chains_resolve_leaders_first_and_cycles_drop_out() -> None:
    chain = [Mimic("c", "b", 2.0), Mimic("b", "a", 3.0, 1.0)]
    assert follow(chain[::-1], {"a": 1.0}) == {"a": 1.0, "b": 4.0, "c": 8.0}
    text = gripper(COUPLED).replace(
        b'<origin xyz="0 0.05 0"/>', b'<origin xyz="0 0.05 0"/><mimic joint="right_joint"/>'
    )
    doc = parse_urdf(text, "cycle.urdf")  # left mimics right mimics left: neither is set
    assert mimics(doc.joints) == []


def test_check_samples_and_poses_set_followers_from_leaders() -> None:
    from armcli.check.context import Context, poses
    from armcli.check.findings import Collector
    from armcli.check.options import CheckOptions
    from armcli.check.structure import check
    from armcli.robot import sampling
    from armcli.robot.model import Robot

    doc = parse_urdf(gripper(COUPLED), "g.urdf")
    robot = Robot.load(doc, strict=False)
    model = robot.model
    sample = sampling.configurations(robot)
    assert len(sample) > 2
    for values, q in sample:
        assert values["right_joint"] == pytest.approx(0.035 - values["left_joint"], abs=1e-15)
        assert q[model.joints[model.getJointId("right_joint")].idx_q] == values["right_joint"]
    out = Collector("g.urdf")
    ctx = Context(doc, CheckOptions(), out, check(doc, out), robot=robot)
    by_name = dict(poses(ctx))
    assert by_name["lower"] == {"left_joint": 0.0, "right_joint": 0.035}
    assert by_name["upper"] == pytest.approx({"left_joint": 0.035, "right_joint": 0.0})


@pytest.mark.parametrize(("mimic", "verdict"), [(COUPLED, "Never"), ("", "checked")])
def test_collision_matrix_samples_followers_with_their_leader(mimic: str, verdict: str) -> None:
    from armcli.ros.collision_matrix import compute_collision_matrix

    matrix = compute_collision_matrix(gripper(mimic), samples=400, seed=1, source="g.urdf")
    never = {(d.link1, d.link2) for d in matrix.disabled if d.reason == "Never"}
    checked = {(e.link1, e.link2) for e in matrix.enabled}
    assert ("left", "right") in (never if verdict == "Never" else checked)
