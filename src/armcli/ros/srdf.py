"""Spec + collision matrix -> the SRDF that MoveIt's Setup Assistant would otherwise make by hand.

Contents: the planning group `arm` (the chain from the arm's root link to the
tool link), the spec's named poses as `group_state`s, an end effector on the
tool link, and the `disable_collisions` entries of the collision matrix.

No virtual joint: the root link `base_footprint` is the planning frame. A
fixed virtual joint (world -> base_footprint) would give base_footprint a
second TF parent as soon as the diff-drive plugin publishes odom ->
base_footprint in Gazebo, and a planar one would need that odometry even in
the Gazebo-less demo.
"""

from __future__ import annotations

from lxml import etree

from armcli.compiler.xmlfmt import fmt, to_bytes
from armcli.robot.tool import spec_tool
from armcli.ros.collision_matrix import CollisionMatrix
from armcli.spec.model import RobotSpec

ARM_GROUP = "arm"
HAND_GROUP = "hand"


def arm_chain(spec: RobotSpec) -> tuple[str, str]:
    """(base_link, tip_link) of the planning chain: the arm root to the tool link."""
    return spec.arm_root(), spec_tool(spec).link


def chain_joints(spec: RobotSpec) -> list[str]:
    """Movable joints on the planning chain, root first."""
    base, tip = arm_chain(spec)
    by_child = {j.child: name for name, j in spec.arm.joints.items()}
    out = []
    link = tip
    while link != base and link in by_child:
        name = by_child[link]
        out.append(name)
        link = spec.arm.joints[name].parent
    return [j for j in reversed(out) if spec.arm.joints[j].type != "fixed"]


def srdf_tree(spec: RobotSpec, matrix: CollisionMatrix) -> etree._Element:
    """The SRDF element tree: arm and hand groups, named poses, end effector, disabled pairs."""
    root = etree.Element("robot", name=spec.name)
    base, tip = arm_chain(spec)
    arm = etree.SubElement(root, "group", name=ARM_GROUP)
    etree.SubElement(arm, "chain", base_link=base, tip_link=tip)
    hand = etree.SubElement(root, "group", name=HAND_GROUP)
    etree.SubElement(hand, "link", name=tip)
    joints = chain_joints(spec)
    for pose_name in spec.poses:
        values = spec.pose(pose_name)
        state = etree.SubElement(root, "group_state", name=pose_name, group=ARM_GROUP)
        for j in joints:
            etree.SubElement(state, "joint", name=j, value=fmt(values.get(j, 0.0)))
    etree.SubElement(
        root,
        "end_effector",
        name=HAND_GROUP,
        parent_link=tip,
        group=HAND_GROUP,
        parent_group=ARM_GROUP,
    )
    for d in matrix.disabled:
        etree.SubElement(root, "disable_collisions", link1=d.link1, link2=d.link2, reason=d.reason)
    return root


def srdf_bytes(spec: RobotSpec, matrix: CollisionMatrix, header: str | None = None) -> bytes:
    """The SRDF document, deterministic for a given spec and matrix."""
    return to_bytes(srdf_tree(spec, matrix), header_comment=header)
