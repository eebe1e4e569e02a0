"""Which links of an imported robot are the arm, and which the mobile base it rides on.

armcli simulates, tunes and plans for the `arm`; a mobile base's wheels (continuous
joints) are not simulated. So when a robot has wheels and a manipulator, the arm is the
subtree under the deepest fixed joint that holds every revolute and prismatic joint and
no continuous one, and the rest is the mobile base, mounted by that fixed joint.
Anything else (an arm alone, a base alone, a humanoid) is imported whole as `arm`;
`--arm-root LINK` chooses the split by hand.
"""

from __future__ import annotations

from dataclasses import dataclass

from armcli.errors import InputError
from armcli.spec.joint_types import LIMITED_TYPES


@dataclass(frozen=True)
class JointEdge:
    """A joint as the split sees it."""

    name: str
    type: str
    parent: str
    child: str


@dataclass(frozen=True)
class Split:
    """The arm's links and joints, and the mount joint (None: the whole robot is the arm)."""

    arm_links: frozenset[str]
    mount: str | None


def _subtree(root: str, joints: list[JointEdge]) -> set[str]:
    out, frontier = {root}, [root]
    while frontier:
        link = frontier.pop()
        for j in joints:
            if j.parent == link and j.child not in out:
                out.add(j.child)
                frontier.append(j.child)
    return out


def split_robot(links: list[str], joints: list[JointEdge], arm_root: str | None = None) -> Split:
    """The arm/base split (see module docstring); InputError for a bad `arm_root`."""
    by_child = {j.child: j for j in joints}
    if arm_root is not None:
        if arm_root not in links:
            raise InputError(f"unknown link {arm_root!r}", field="arm_root")
        mount = by_child.get(arm_root)
        if mount is None:
            return Split(frozenset(links), None)
        if mount.type != "fixed":
            raise InputError(
                f"{arm_root!r} hangs on {mount.type} joint {mount.name!r}; the arm is mounted by "
                "a fixed joint",
                field="arm_root",
            )
        return Split(frozenset(_subtree(arm_root, joints)), mount.name)
    moving = {j.child for j in joints if j.type in LIMITED_TYPES}
    wheels = {j.child for j in joints if j.type == "continuous"}
    if not moving or not wheels:
        return Split(frozenset(links), None)
    best: tuple[int, str] | None = None
    for j in joints:
        if j.type != "fixed":
            continue
        sub = _subtree(j.child, joints)
        if moving <= sub and not (wheels & sub):
            size = len(sub)
            if best is None or size < best[0]:
                best = (size, j.child)
    if best is None:
        return Split(frozenset(links), None)
    root = best[1]
    return Split(frozenset(_subtree(root, joints)), by_child[root].name)
