"""armcli.robot.model: the joint table, `Robot.q` against a hand-built configuration and
closed-form kinematics, the reduced model and the collision model on demand."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from armcli.errors import InputError
from armcli.robot.model import Robot
from armcli.robot.tool import ToolPoint
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.read import parse_urdf
from tests.meshes import prism_triangles, write_stl

EXACT = 1e-12  # same arithmetic, only rounding of cos/sin and one rotation product

# A base, a continuous yaw joint (axis z), a revolute pitch joint (axis y), a prismatic
# slide (axis x), a fixed tool flange and a mimic finger. Each link 1 kg, box collision.
URDF = b"""<robot name="t">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="turret"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="arm"><inertial><origin xyz="0.25 0 0"/><mass value="1"/><inertia ixx="0.01"
    iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="slider"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="finger"><inertial><mass value="0.1"/><inertia ixx="0.001" iyy="0.001"
    izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="flange"/>
  <joint name="yaw" type="continuous"><parent link="base"/><child link="turret"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><dynamics damping="0.5" friction="0.2"/>
    <limit effort="10" velocity="3"/></joint>
  <joint name="pitch" type="revolute"><parent link="turret"/><child link="arm"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit lower="-1" upper="2" effort="20"
    velocity="2"/></joint>
  <joint name="slide" type="prismatic"><parent link="arm"/><child link="slider"/>
    <origin xyz="0.5 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.3" effort="0"
    velocity="1"/></joint>
  <joint name="grip" type="prismatic"><parent link="slider"/><child link="finger"/>
    <axis xyz="0 1 0"/><limit lower="0" upper="0.1" effort="5" velocity="1"/>
    <mimic joint="slide" multiplier="0.5" offset="0.01"/></joint>
  <joint name="flange_joint" type="fixed"><parent link="slider"/><child link="flange"/>
    <origin xyz="0.1 0 0"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.load(parse_urdf(URDF, "t.urdf"))


def test_joint_table_reads_the_urdf(robot: Robot) -> None:
    # every number below is the URDF text's above
    assert robot.names == ("yaw", "pitch", "slide", "grip")
    yaw, pitch, slide, _ = robot.joints
    assert yaw.continuous and (yaw.lower, yaw.upper) == (-math.inf, math.inf)
    assert yaw.span == (-math.pi, math.pi)
    assert (yaw.damping, yaw.friction, yaw.effort, yaw.velocity) == (0.5, 0.2, 10.0, 3.0)
    assert not pitch.continuous and (pitch.lower, pitch.upper) == (-1.0, 2.0) == pitch.span
    assert slide.effort == math.inf  # effort="0": no limit
    assert [j.idx_v for j in robot.joints] == [0, 1, 2, 3]
    assert [j.idx_q for j in robot.joints] == [0, 2, 3, 4]  # yaw takes (cos, sin)


def test_mimics_tool_and_leaders(robot: Robot) -> None:
    assert [(m.follower, m.leader) for m in robot.mimics] == [("grip", "slide")]
    assert [j.name for j in robot.leaders] == ["yaw", "pitch", "slide"]
    assert robot.follow({"slide": 0.2}) == {"slide": 0.2, "grip": 0.5 * 0.2 + 0.01}
    # robot.tool's rule: the mimic finger does not count (issue 31); slider and flange are
    # 3 movable joints deep, and the flange is named as a tool frame
    assert robot.tool == ToolPoint("flange")


def test_q_matches_a_hand_built_configuration(robot: Robot) -> None:
    x = {"yaw": 2.5, "pitch": -0.7, "slide": 0.12, "grip": 0.03}
    expected = np.array([math.cos(2.5), math.sin(2.5), -0.7, 0.12, 0.03])  # (cos, sin) layout
    assert np.array_equal(robot.q(x), expected)
    assert np.array_equal(robot.q([2.5, -0.7, 0.12, 0.03]), expected)  # by tree order
    pitch = robot.joint("pitch")
    assert np.array_equal(robot.q([0.4], joints=[pitch], base=expected),
                          np.array([*expected[:2], 0.4, *expected[3:]]))  # fmt: skip
    assert np.array_equal(robot.q({"nope": 1.0}), robot.neutral())  # unknown names ignored


def test_joint_map_builds_the_same_q_vectorised(robot: Robot) -> None:
    # the planner's per-state map: chosen joints from x, the others at rest, followers follow
    rest = {"pitch": 0.3}
    fast = robot.joint_map(["yaw", "slide"], rest)
    rng = np.random.default_rng(0)
    for x in rng.uniform(-3.0, 3.0, size=(50, 2)):
        slow = robot.q(robot.follow({**rest, "yaw": x[0], "slide": x[1]}))
        np.testing.assert_array_equal(fast.q(x), slow)
    q = fast.q(np.array([math.pi / 2, 0.2]))
    yaw, grip = robot.joint("yaw"), robot.joint("grip")
    assert q[yaw.idx_q : yaw.idx_q + 2] == pytest.approx([0.0, 1.0], abs=1e-15)
    assert q[grip.idx_q] == pytest.approx(0.5 * 0.2 + 0.01)  # the mimic coupling by hand


def test_q_poses_the_robot_like_closed_form_kinematics(robot: Robot) -> None:
    """Flange at (yaw, pitch, s): Rz(yaw) [0, 0, 0.3] + Rz(yaw) Ry(pitch) [0.6 + s, 0, 0]."""
    yaw, pitch, s = 2.0, 0.5, 0.2
    q = robot.q({"yaw": yaw, "pitch": pitch, "slide": s})
    pin.framesForwardKinematics(robot.model, robot.data, q)
    got = robot.data.oMf[robot.model.getFrameId("flange")].translation
    Rz = np.array(
        [[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]]
    )
    Ry = np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0],
                   [-math.sin(pitch), 0, math.cos(pitch)]])  # fmt: skip
    expected = Rz @ np.array([0, 0, 0.3]) + Rz @ Ry @ np.array([0.5 + s + 0.1, 0, 0])
    assert np.allclose(got, expected, atol=EXACT)


def test_reduced_locks_the_others_at_neutral(robot: Robot) -> None:
    arm = robot.reduced(["pitch", "slide"])
    assert arm.names == ("pitch", "slide") and arm.model.nq == 2
    assert arm.mimics == ()  # grip is locked: no coupling left
    assert robot.reduced(robot.names) is robot
    with pytest.raises(InputError, match="unknown joint 'elbow'; valid: yaw, pitch") as err:
        robot.reduced(["elbow"])
    assert err.value.field == "joints"
    with pytest.raises(InputError, match="listed twice"):
        robot.reduced(["pitch", "pitch"])


def test_joint_lists_the_valid_names(robot: Robot) -> None:
    with pytest.raises(InputError, match="valid: yaw, pitch, slide, grip"):
        robot.joint("elbow")


def test_collision_model_on_demand(robot: Robot) -> None:
    gm = robot.collision_model()
    links = sorted(robot.model.frames[g.parentFrame].name for g in gm.geometryObjects)
    assert links == ["base", "turret"]  # the two <collision> elements of URDF
    with pytest.raises(InputError, match="no URDF text"):
        Robot(robot.model).collision_model()


def test_mass_and_data(robot: Robot) -> None:
    assert robot.mass == pytest.approx(3.1, abs=EXACT)  # 1 + 1 + 1 + 0.1 kg in URDF
    assert robot.data is robot.data


def test_collision_model_resolves_meshes_inside_the_allowed_roots(tmp_path: Path) -> None:
    write_stl(tmp_path / "meshes" / "box.stl", prism_triangles(0.05, 0.1, 4))
    mesh = b'<mesh filename="meshes/box.stl"/>'
    text = URDF.replace(b'<box size="0.1 0.1 0.1"/>', mesh)
    (tmp_path / "t.urdf").write_bytes(text)
    robot = Robot.load(parse_urdf(text, str(tmp_path / "t.urdf")))
    gm = robot.collision_model(MeshSearch())
    real = (tmp_path / "meshes" / "box.stl").resolve()
    assert [g.meshPath for g in gm.geometryObjects if g.meshPath.endswith(".stl")] == [str(real)]
    gone = Robot.load(parse_urdf(text.replace(b"box.stl", b"gone.stl"),
                                      str(tmp_path / "t.urdf")))  # fmt: skip
    with pytest.raises(InputError, match=r"mesh 'meshes/gone\.stl' cannot be found"):
        gone.collision_model(MeshSearch())


def test_limit_arrays_are_read_only_views_of_the_model(robot: Robot) -> None:
    # the URDF's numbers, per joint in tree order (yaw continuous: no stops)
    assert robot.lower.tolist() == [-math.inf, -1.0, 0.0, 0.0]
    assert robot.upper.tolist() == [math.inf, 2.0, 0.3, 0.1]
    assert robot.effort.tolist() == [10.0, 20.0, math.inf, 5.0]  # slide's effort="0": none
    assert robot.velocity.tolist() == [3.0, 2.0, 1.0, 1.0]
    assert robot.damping.tolist() == [0.5, 0.0, 0.0, 0.0]
    assert robot.friction.tolist() == [0.2, 0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match="read-only"):
        robot.lower[1] = 0.0


def test_with_limits_is_a_new_robot_over_a_copied_model(robot: Robot) -> None:
    other = robot.with_limits(effort=np.array([1.0, 0.0, -2.0, 4.0]), lower=np.full(4, -0.5))
    assert other.effort.tolist() == [1.0, math.inf, math.inf, 4.0]  # <= 0: no limit, as read
    assert other.lower.tolist() == [-math.inf, -0.5, -0.5, -0.5]  # yaw stays continuous
    assert robot.effort.tolist() == [10.0, 20.0, math.inf, 5.0]  # the original unchanged
    assert other.mimics == robot.mimics and other.tool == robot.tool  # couplings survive
    with pytest.raises(ValueError, match="unknown limit 'stiffness'"):
        robot.with_limits(stiffness=np.zeros(4))


def test_scaled_masses_and_friction(robot: Robot) -> None:
    scaled = robot.scaled([2.0, 1.0, 1.0, 0.5], [1.0, 1.0, 3.0, 1.0])
    assert scaled.mass == pytest.approx(2.0 + 1.0 + 1.0 + 0.05, abs=EXACT)  # URDF masses
    assert scaled.friction.tolist() == [0.2, 0.0, 0.0, 0.0]  # 3 x 0: still none
    assert scaled.model.inertias[1].lever.tolist() == robot.model.inertias[1].lever.tolist()
    assert robot.scaled([1.0] * 4, [2.0, 1.0, 1.0, 1.0]).friction[0] == pytest.approx(0.4)


def test_a_point_mass_moves_the_centre_of_mass(robot: Robot) -> None:
    q = robot.q({"yaw": 0.3, "pitch": -0.4, "slide": 0.1})
    loaded = robot.with_point_mass("flange", (0.0, 0.0, 0.05), 2.0)
    point = robot.point_position("flange", (0.0, 0.0, 0.05), q)
    expected = (robot.mass * robot.center_of_mass(q) + 2.0 * point) / (robot.mass + 2.0)
    np.testing.assert_allclose(loaded.center_of_mass(q), expected, atol=EXACT)
    assert loaded.mass == pytest.approx(robot.mass + 2.0, abs=EXACT)


def test_each_thread_has_its_own_data(robot: Robot) -> None:
    import threading

    seen = []
    thread = threading.Thread(target=lambda: seen.append(robot.data))
    thread.start()
    thread.join()
    assert seen[0] is not robot.data and robot.data is robot.data
