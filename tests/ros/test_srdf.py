"""SRDF: well-formed, names what the URDF has, and carries the spec's poses and the matrix."""

from __future__ import annotations

from pathlib import Path
from typing import cast

import pytest
from lxml import etree

from armcli.ros.collision_matrix import CollisionMatrix, DisabledPair, Reason
from armcli.ros.srdf import arm_chain, chain_joints, srdf_bytes
from armcli.spec.load import load_spec
from armcli.spec.model import RobotSpec


@pytest.fixture(scope="module")
def spec(default_spec_path: Path) -> RobotSpec:
    return load_spec(default_spec_path)


@pytest.fixture(scope="module")
def matrix() -> CollisionMatrix:
    """A hand-made matrix: the writer must copy it, whatever the sampler would say."""
    return CollisionMatrix(
        links=("arm_base_link", "base_link", "forearm_link", "hand_link"),
        disabled=(
            DisabledPair("arm_base_link", "base_link", "Adjacent"),
            DisabledPair("arm_base_link", "hand_link", "Never"),
            DisabledPair("base_link", "hand_link", "Default"),
        ),
        enabled=(),
        samples=1,
        seed=0,
    )


@pytest.fixture(scope="module")
def srdf(spec: RobotSpec, matrix: CollisionMatrix) -> etree._Element:
    return etree.fromstring(srdf_bytes(spec, matrix, header="test"))


@pytest.fixture(scope="module")
def urdf(built_dir: Path) -> etree._Element:
    return etree.parse(str(built_dir / "my_robot.urdf")).getroot()


def test_chain_is_the_arm_from_root_to_the_tool_link(spec: RobotSpec) -> None:
    # specs/my_robot.yaml: arm_base_link -> forearm_link -> hand_link, tool on hand_link
    assert arm_chain(spec) == ("arm_base_link", "hand_link")
    assert chain_joints(spec) == ["arm_base_forearm_joint", "forearm_hand_joint"]


def test_groups_end_effector_and_no_virtual_joint(srdf: etree._Element) -> None:
    assert srdf.get("name") == "my_robot"
    (chain,) = srdf.findall("group[@name='arm']/chain")
    assert (chain.get("base_link"), chain.get("tip_link")) == ("arm_base_link", "hand_link")
    (eef,) = srdf.findall("end_effector")
    assert eef.get("parent_link") == "hand_link"
    assert eef.get("parent_group") == "arm"
    assert srdf.find(f"group[@name='{eef.get('group')}']") is not None
    assert eef.get("group") != eef.get("parent_group")  # MoveIt: a group cannot be its own parent
    assert srdf.find("virtual_joint") is None


def test_group_states_are_the_spec_poses(srdf: etree._Element, spec: RobotSpec) -> None:
    states = srdf.findall("group_state")
    assert [s.get("name") for s in states] == list(spec.poses)
    for state in states:
        assert state.get("group") == "arm"
        values = {j.get("name"): float(j.get("value", "nan")) for j in state.findall("joint")}
        assert values == spec.pose(state.get("name", ""))  # same floats, exactly


def test_disable_collisions_copy_the_matrix(srdf: etree._Element, matrix: CollisionMatrix) -> None:
    entries = [
        DisabledPair(d.get("link1", ""), d.get("link2", ""), cast(Reason, d.get("reason")))
        for d in srdf.findall("disable_collisions")
    ]
    assert tuple(entries) == matrix.disabled


def test_every_name_exists_in_the_urdf(srdf: etree._Element, urdf: etree._Element) -> None:
    links = {lk.get("name") for lk in urdf.findall("link")}
    joints = {j.get("name") for j in urdf.findall("joint")}
    named_links = [c.get(a) for c in srdf.iter("chain") for a in ("base_link", "tip_link")]
    named_links += [lk.get("name") for lk in srdf.findall("group/link")]
    named_links += [e.get("parent_link") for e in srdf.findall("end_effector")]
    named_links += [
        d.get(a) for d in srdf.findall("disable_collisions") for a in ("link1", "link2")
    ]
    assert set(named_links) <= links
    assert {j.get("name") for j in srdf.findall("group_state/joint")} <= joints


def test_output_is_deterministic(spec: RobotSpec, matrix: CollisionMatrix) -> None:
    assert srdf_bytes(spec, matrix) == srdf_bytes(spec, matrix)
