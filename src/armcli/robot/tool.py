"""The end-effector point every command reports, so check, simulate, view and render agree.

With a spec, it is the spec's `arm.tool` (a point fixed in a link, such as the hand's
tip). Otherwise it is the origin of the deepest link (of the spec's arm, or of a foreign
URDF): the link with the most movable joints between it and the root, the first in file
order on ties. Fixed joints do not count, so a sensor frame fixed to the last moving link
does not outrank the link itself unless it comes first in the file. A gripper's fingers
(prismatic joints two of which share a parent link, or tied by a mimic) do not count
either, and a finger is never the tool point: OpenManipulator-X's tool is its
`end_effector_link`, not `gripper_left_link` (issue 31). Among tied links, one named as a
tool (TOOL_WORDS: `tool0`, `flange`, `end_effector_link`, `*_tcp`, ...) wins. MoveIt's planning
chain (`ros.srdf`) ends at the same link.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from armcli.urdf.doc import Urdf

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec


@dataclass(frozen=True)
class ToolPoint:
    """The end-effector point: `xyz` [m] fixed in `link`'s frame."""

    link: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def label(self) -> str:
        """How reports name the point: the link, plus the offset [m] when there is one."""
        if not any(self.xyz):
            return self.link
        return f"{self.link} + ({', '.join(f'{x:g}' for x in self.xyz)})"


TOOL_WORDS = ("tool", "tcp", "flange", "end_effector", "eef", "ee_link", "grasp")  # frame names


@dataclass(frozen=True)
class JointLink:
    """What the tool rule needs of a joint: its links, its type, what it follows.

    `mimic` is, for a mimic joint, the child link of the joint it follows.
    """

    parent: str
    child: str
    type: str
    mimic: str | None = None


def finger_links(joints: Sequence[JointLink]) -> set[str]:
    """Children of a gripper's finger joints.

    Prismatic joints that share their parent link with another prismatic joint (a
    two-finger gripper) or follow another joint (a mimic finger). A prismatic joint that
    is only followed may be an axis of the arm, and stays one.
    """
    prismatic = [j for j in joints if j.type == "prismatic"]
    return {
        j.child
        for j in prismatic
        if sum(k.parent == j.parent for k in prismatic) > 1 or j.mimic is not None
    }


def deepest_link(links: Sequence[str], joints: Sequence[JointLink]) -> str:
    """The link with the most movable joints above it, fingers aside (see the module).

    Ties: a link named as a tool, else the first in `links`. A malformed tree (a cycle)
    stays bounded.
    """
    fingers = finger_links(joints)
    parent = {j.child: (j.parent, j.type != "fixed") for j in joints}

    def depth(link: str) -> int:
        n, cur = 0, link
        for _ in range(len(parent) + 1):
            if cur in fingers:
                return -1  # a finger, or a link carried by one: never the tool
            if cur not in parent:
                break
            cur, moves = parent[cur]
            n += moves
        return n

    def named_tool(link: str) -> bool:
        return any(w in link.lower() for w in TOOL_WORDS)

    return max(links, key=lambda link: (depth(link), named_tool(link)))


def spec_tool(spec: RobotSpec) -> ToolPoint:
    """The spec's `arm.tool`, or else the deepest link of its arm (the rule above)."""
    t = spec.arm.tool
    if t is not None:
        return ToolPoint(t.link, (float(t.xyz[0]), float(t.xyz[1]), float(t.xyz[2])))
    joints = [
        JointLink(j.parent, j.child, j.type, _mimic_child(j.mimic.joint, spec.arm.joints))
        if j.mimic is not None
        else JointLink(j.parent, j.child, j.type)
        for j in spec.arm.joints.values()
    ]
    return ToolPoint(deepest_link(list(spec.arm.links), joints))


def tool_point(urdf: Urdf, spec: RobotSpec | None = None) -> ToolPoint | None:
    """The tool point of this URDF (see the module docstring); None for a URDF without links."""
    names = [lk.name for lk in urdf.links]
    if spec is not None and (tool := spec_tool(spec)).link in names:
        return tool
    if not names:
        return None
    by_name = {j.name: j for j in urdf.joints}
    joints = [
        JointLink(
            str(j.parent),
            str(j.child),
            j.type,
            str(by_name[j.mimic].child) if j.mimic in by_name else None,
        )
        for j in urdf.joints
    ]
    return ToolPoint(deepest_link(names, joints))


def _mimic_child(lead: str, joints: Any) -> str | None:
    """The child link of the joint `lead` a spec joint mimics (None when there is none)."""
    j = joints.get(lead)
    return None if j is None else str(j.child)
