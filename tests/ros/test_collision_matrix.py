"""Setup-Assistant-style collision matrix: reasons checked against geometry worked out by hand."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from lxml import etree

from armcli.compiler.expand import expand_urdfs
from armcli.errors import InputError
from armcli.ros.collision_matrix import adjacent_pairs, compute_collision_matrix
from armcli.spec.load import load_spec
from armcli.urdf.read import parse_urdf

# Test robot (all lengths in m), built below:
#   base (box) --revolute z, limits [lo, hi]--> arm: 1 x 0.02 x 0.02 bar along +x from the axis
#   base --fixed--> post: cylinder r = 0.05 standing at distance D = 0.6 from the axis, azimuth PHI
#   base --fixed--> blob: sphere r = 0.1 centred on the axis, so it always overlaps the arm's root
#   base --fixed--> frame (no geometry) --fixed--> tool: small box far away
ARM_HALF_WIDTH = 0.01
POST_RADIUS = 0.05
POST_DISTANCE = 0.6
POST_AZIMUTH = 0.5  # [rad]
# The bar touches the post when the post centre is within POST_RADIUS + ARM_HALF_WIDTH of the
# bar's centre line: D·|sin(θ - PHI)| <= r + w/2, i.e. |θ - PHI| <= asin((r + w/2) / D).
HALF_ANGLE = math.asin((POST_RADIUS + ARM_HALF_WIDTH) / POST_DISTANCE)
SAMPLES = 2000
SIGMAS = 5.0  # binomial tolerance on the sampled collision fraction


def _origin(parent: etree._Element, xyz: str = "0 0 0") -> None:
    etree.SubElement(parent, "origin", xyz=xyz, rpy="0 0 0")


def _link(root: etree._Element, name: str, shape: str | None = None, **dims: str) -> None:
    link = etree.SubElement(root, "link", name=name)
    inertial = etree.SubElement(link, "inertial")
    etree.SubElement(inertial, "mass", value="1")
    etree.SubElement(
        inertial, "inertia", ixx="0.01", iyy="0.01", izz="0.01", ixy="0", ixz="0", iyz="0"
    )
    if shape is not None:
        xyz = dims.pop("xyz", "0 0 0")
        col = etree.SubElement(link, "collision")
        _origin(col, xyz)
        etree.SubElement(etree.SubElement(col, "geometry"), shape, **dims)


def _joint(root: etree._Element, name: str, kind: str, parent: str, child: str, xyz: str) -> None:
    j = etree.SubElement(root, "joint", name=name, type=kind)
    etree.SubElement(j, "parent", link=parent)
    etree.SubElement(j, "child", link=child)
    _origin(j, xyz)
    if kind == "revolute":
        etree.SubElement(j, "axis", xyz="0 0 1")


def sweep_robot(lower: float, upper: float) -> bytes:
    root = etree.Element("robot", name="sweep")
    _link(root, "base", "box", size="0.2 0.2 0.1", xyz="0 0 -0.2")
    _link(root, "arm", "box", size=f"1 {2 * ARM_HALF_WIDTH} 0.02", xyz="0.5 0 0")
    _link(root, "post", "cylinder", radius=str(POST_RADIUS), length="0.1")
    _link(root, "blob", "sphere", radius="0.1")
    _link(root, "frame")
    _link(root, "tool", "box", size="0.05 0.05 0.05")
    _joint(root, "swing", "revolute", "base", "arm", "0 0 0")
    arm_joint = root.find("joint[@name='swing']")
    assert arm_joint is not None
    etree.SubElement(
        arm_joint, "limit", lower=repr(lower), upper=repr(upper), effort="1", velocity="1"
    )
    px, py = POST_DISTANCE * math.cos(POST_AZIMUTH), POST_DISTANCE * math.sin(POST_AZIMUTH)
    _joint(root, "post_joint", "fixed", "base", "post", f"{px!r} {py!r} 0")
    _joint(root, "blob_joint", "fixed", "base", "blob", "0 0 0")
    _joint(root, "frame_joint", "fixed", "base", "frame", "-3 0 0")
    _joint(root, "tool_joint", "fixed", "frame", "tool", "-1 0 0")
    return etree.tostring(root)


def test_reasons_on_a_robot_with_known_geometry() -> None:
    m = compute_collision_matrix(sweep_robot(-1.0, 1.0), samples=SAMPLES, seed=3)
    # parent/child pairs; base-tool through the geometry-less `frame` link, as MoveIt does
    for a, b in [("arm", "base"), ("base", "post"), ("base", "blob"), ("base", "tool")]:
        assert m.reason(a, b) == "Adjacent"
    # the blob overlaps the arm's root at every angle, so it is caught at the default state
    assert m.reason("arm", "blob") == "Default"
    # far apart at every angle
    for a, b in [("blob", "post"), ("arm", "tool"), ("post", "tool"), ("blob", "tool")]:
        assert m.reason(a, b) == "Never"
    # the bar sweeps through the post for |θ - PHI| <= HALF_ANGLE: checked, never disabled
    assert m.reason("arm", "post") is None
    (pair,) = m.enabled
    assert (pair.link1, pair.link2) == ("arm", "post")
    p = 2 * HALF_ANGLE / 2.0  # fraction of the uniform range [-1, 1] that collides
    sigma = math.sqrt(SAMPLES * p * (1 - p))
    assert abs(pair.collisions - SAMPLES * p) <= SIGMAS * sigma


def test_an_always_colliding_pair_is_never_marked_never() -> None:
    for seed in range(3):
        m = compute_collision_matrix(sweep_robot(-1.0, 1.0), samples=50, seed=seed)
        assert m.reason("arm", "blob") != "Never"


def test_default_state_is_midrange_when_zero_is_outside_the_limits() -> None:
    # MoveIt's default state: 0 if within the limits, else the middle of the range.
    # [0.3, 0.7]: the middle is the post's azimuth, so the bar points straight through it.
    m = compute_collision_matrix(sweep_robot(0.3, 0.7), samples=20, seed=0)
    assert m.reason("arm", "post") == "Default"
    # [0.45, 1.45]: clamping 0 would give 0.45 (touching the post), the middle 0.95 misses it
    assert abs(0.45 - POST_AZIMUTH) < HALF_ANGLE < abs(0.95 - POST_AZIMUTH)
    m = compute_collision_matrix(sweep_robot(0.45, 1.45), samples=20, seed=0)
    assert m.reason("arm", "post") != "Default"


def test_same_seed_same_matrix_and_seed_matters() -> None:
    urdf = sweep_robot(-1.0, 1.0)
    a = compute_collision_matrix(urdf, samples=300, seed=11)
    b = compute_collision_matrix(urdf, samples=300, seed=11)
    assert a == b
    counts = {compute_collision_matrix(urdf, samples=300, seed=s).enabled for s in range(4)}
    assert len(counts) > 1  # the count of a 10 % event over 300 draws varies with the seed


def test_sample_count_must_be_positive() -> None:
    with pytest.raises(InputError, match="at least 1"):
        compute_collision_matrix(sweep_robot(-1.0, 1.0), samples=0)


@pytest.fixture(scope="module")
def robot_urdf(default_spec_path: Path) -> bytes:
    return expand_urdfs(load_spec(default_spec_path))["my_robot.urdf"]


def test_default_robot_adjacent_pairs_are_the_spec_joints(
    default_spec_path: Path, robot_urdf: bytes
) -> None:
    spec = load_spec(default_spec_path)
    solid = {name for name, link in spec.all_links().items() if link.geometry is not None}
    expected = {
        tuple(sorted((j.parent, j.child)))
        for j in spec.all_joints().values()
        if j.parent in solid and j.child in solid
    }
    assert adjacent_pairs(parse_urdf(robot_urdf, "my_robot.urdf")) == expected
    m = compute_collision_matrix(robot_urdf, samples=500, seed=0)
    assert {(d.link1, d.link2) for d in m.disabled if d.reason == "Adjacent"} == expected
    assert "base_footprint" not in m.links  # no collision geometry, so never in a pair
    n = len(m.links)
    assert len(m.disabled) + len(m.enabled) == n * (n - 1) // 2


def test_a_pose_at_the_stop_lays_the_forearm_on_the_base(
    default_spec_path: Path, robot_urdf: bytes
) -> None:
    # At arm_base_forearm_joint = pi/2 the forearm (r = 0.02) lies horizontally with its axis at
    # mount z 0.2 + arm base 0.02 = 0.22 above base_link's origin, so its underside is at 0.20,
    # exactly the top of the 0.2 m high base box (centred at z = 0.1): touching contact.
    spec = load_spec(default_spec_path)
    poses = {name: spec.pose(name) for name in spec.poses}
    at_stop = {"arm_base_forearm_joint": math.pi / 2, "forearm_hand_joint": math.pi / 2}
    m = compute_collision_matrix(robot_urdf, samples=200, seed=0, poses={**poses, "stop": at_stop})
    forearm_pair = ("base_link", "forearm_link")
    # random states almost never land exactly on the limit; the named pose keeps the pair checked
    assert m.reason(*forearm_pair) is None
    assert ("stop", *forearm_pair) in m.pose_collisions
    # the shipped poses collide with nothing (`folded` stops at 1.5 rad: issue 31)
    assert not [p for p in m.pose_collisions if p[0] in spec.poses]
