"""Which part of an imported robot is the arm: the wheels stay on the base."""

from __future__ import annotations

import pytest

from armcli.errors import InputError
from armcli.importer.split import JointEdge, split_robot

LINKS = ["footprint", "base", "wheel_l", "wheel_r", "mast", "arm_base", "upper", "fore"]
JOINTS = [
    JointEdge("j0", "fixed", "footprint", "base"),
    JointEdge("wl", "continuous", "base", "wheel_l"),
    JointEdge("wr", "continuous", "base", "wheel_r"),
    JointEdge("m", "fixed", "base", "mast"),
    JointEdge("mount", "fixed", "mast", "arm_base"),
    JointEdge("s", "revolute", "arm_base", "upper"),
    JointEdge("e", "revolute", "upper", "fore"),
]


def test_the_smallest_fixed_subtree_with_every_arm_joint_and_no_wheel() -> None:
    split = split_robot(LINKS, JOINTS)
    assert split.mount == "mount"
    assert split.arm_links == {"arm_base", "upper", "fore"}


def test_no_wheels_or_no_arm_joints_keeps_the_robot_whole() -> None:
    arm_only = [j for j in JOINTS if j.type != "continuous"]
    assert split_robot(LINKS, arm_only).mount is None
    base_only = [j for j in JOINTS if j.type != "revolute"]
    assert split_robot(LINKS, base_only).mount is None


def test_arm_root_by_hand() -> None:
    assert split_robot(LINKS, JOINTS, "mast").arm_links == {"mast", "arm_base", "upper", "fore"}
    with pytest.raises(InputError, match="unknown link"):
        split_robot(LINKS, JOINTS, "nowhere")
    with pytest.raises(InputError, match="continuous joint 'wl'"):
        split_robot(LINKS, JOINTS, "wheel_l")
