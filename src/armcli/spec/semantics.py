"""Cross-reference rules of a spec that field validation cannot express.

Parents and children exist, each part is one tree, names are unique across
parts, plugin/gain/pose joint names exist, poses are within limits. Returns
problems with dotted field paths; `spec.spec_from_doc` adds file and line.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from armcli.errors import Problem
from armcli.io.names import did_you_mean
from armcli.io.yaml import dotted
from armcli.spec.graph import root_links
from armcli.spec.joint_types import ONE_DOF_TYPES
from armcli.spec.model import Joint, Link, RobotSpec


def semantic_problems(spec: RobotSpec) -> list[Problem]:
    """Every cross-reference problem of `spec`, with dotted field paths; [] if none."""
    out: list[Problem] = []

    def add(path: tuple[str | int, ...], msg: str) -> None:
        out.append(Problem(dotted(path), msg))

    base_links = spec.mobile_base.links if spec.mobile_base else {}
    base_joints = spec.mobile_base.joints if spec.mobile_base else {}
    for name in spec.arm.links:
        if name in base_links:
            add(("arm", "links", name), "link name already used in mobile_base.links")
    for name in spec.arm.joints:
        if name in base_joints:
            add(("arm", "joints", name), "joint name already used in mobile_base.joints")

    parts: list[tuple[str, dict[str, Link], dict[str, Joint]]] = [
        ("arm", spec.arm.links, spec.arm.joints)
    ]
    if spec.mobile_base is not None:
        parts.append(("mobile_base", base_links, base_joints))
    for part, links, joints in parts:
        _tree_problems(part, links, joints, add)
        for lname, link in links.items():
            _material_problems(spec, (part, "links", lname), link, add)

    arm_movable = set(spec.movable_arm_joints()) if not out else set()
    all_joints = {**base_joints, **spec.arm.joints}
    _plugin_problems(spec, all_joints, add)
    _mount_problems(spec, all_joints, add)
    _mimic_problems(spec, add)
    _control_problems(spec, all_joints, add)
    _sensor_problems(spec, add)
    for jname in spec.control.gains:
        if jname not in spec.arm.joints:
            add(("control", "gains", jname), _unknown("arm joint", jname, spec.arm.joints))
        elif (m := spec.arm.joints[jname].mimic) is not None:
            add(("control", "gains", jname), f"mimics {m.joint}: give gains to the lead joint")
    _pose_problems(spec, arm_movable, add)
    return out


def _material_problems(
    spec: RobotSpec, path: tuple[str, ...], link: Link, add: Callable[..., None]
) -> None:
    """Material names a link uses exist in `materials`."""
    known = _names(spec.materials)
    if isinstance(link.material, str) and link.material not in spec.materials:
        add((*path, "material"), f"unknown material {link.material!r}; known: {known}")
    for i, shape in enumerate(link.visual):
        if isinstance(shape.material, str) and shape.material not in spec.materials:
            add(
                (*path, "visual", i, "material"),
                f"unknown material {shape.material!r}; known: {known}",
            )


def _mimic_problems(spec: RobotSpec, add: Callable[..., None]) -> None:
    """A mimic joint follows a moving joint of the same part that is no follower itself."""
    parts = [("arm", spec.arm.joints)]
    if spec.mobile_base is not None:
        parts.append(("mobile_base", spec.mobile_base.joints))
    for part, joints in parts:
        for jname, j in joints.items():
            if j.mimic is None:
                continue
            lead = joints.get(j.mimic.joint)
            path = (part, "joints", jname, "mimic", "joint")
            if lead is None:
                add(path, f"unknown {part} joint; known: {_names(joints)}")
            elif j.mimic.joint == jname:
                add(path, "a joint cannot mimic itself")
            elif lead.type not in ONE_DOF_TYPES:
                add(path, f"{j.mimic.joint} is {lead.type}: a lead joint must move")
            elif lead.mimic is not None:
                add(path, f"{j.mimic.joint} mimics {lead.mimic.joint}: follow that one")


def _control_problems(
    spec: RobotSpec, all_joints: dict[str, Joint], add: Callable[..., None]
) -> None:
    """ros2_control joints exist and move."""
    if spec.ros2_control is None:
        return
    for jname in spec.ros2_control.joints:
        j = all_joints.get(jname)
        if j is None:
            add(("ros2_control", "joints", jname), f"unknown joint; known: {_names(all_joints)}")
        elif j.type == "fixed":
            add(("ros2_control", "joints", jname), "a fixed joint has no interfaces")


def _sensor_problems(spec: RobotSpec, add: Callable[..., None]) -> None:
    """Sensors sit on known links, stamp known frames and publish distinct topics."""
    links = spec.all_links()
    topics: dict[str, str] = {}
    for name, s in spec.sensors.items():
        for role in ("link", "frame"):
            value = getattr(s, role)
            if value is not None and value not in links:
                add(("sensors", name, role), _unknown("link", value, links, named=True))
        if s.topic in topics:
            add(("sensors", name, "topic"), f"{s.topic!r} is already sensor {topics[s.topic]}'s")
        topics[s.topic] = name


def _mount_problems(spec: RobotSpec, all_joints: dict[str, Joint], add: Any) -> None:
    """The mount joint: needed with a base, on a base link, under an unused name."""
    base_links = spec.mobile_base.links if spec.mobile_base else {}
    if spec.mount is not None:
        if spec.mobile_base is None:
            add(("mount",), "a mount needs a mobile_base")
        elif spec.mount.parent not in base_links:
            add(("mount", "parent"), _unknown("link", spec.mount.parent, base_links))
        if spec.mount.joint in all_joints:
            add(("mount", "joint"), "joint name already used")
    elif spec.mobile_base is not None:
        add(("mount",), "a mobile_base needs a mount joint for the arm")


def _pose_problems(spec: RobotSpec, arm_movable: set[str], add: Any) -> None:
    """Named poses: known moving arm joints, values within the limits."""
    for pname, pose in spec.poses.items():
        for jname, value in pose.items():
            j = spec.arm.joints.get(jname)
            if j is None or (arm_movable and jname not in arm_movable):
                add(("poses", pname, jname), _unknown("arm joint", jname, spec.arm.joints))
            elif j.mimic is not None:
                add(("poses", pname, jname), f"mimics {j.mimic.joint}: give the lead joint")
            elif (
                (b := j.bounds) is not None
                and b[0] <= b[1]
                and not (b[0] - 1e-12 <= value <= b[1] + 1e-12)
            ):
                add(
                    ("poses", pname, jname),
                    f"{value:g} is outside the joint limits [{b[0]:g}, {b[1]:g}]",
                )


def _tree_problems(part: str, links: dict[str, Link], joints: dict[str, Joint], add: Any) -> None:
    children: dict[str, str] = {}
    for jname, j in joints.items():
        for role in ("parent", "child"):
            if getattr(j, role) not in links:
                add((part, "joints", jname, role), _unknown("link", getattr(j, role), links))
        if j.child in children:
            add(
                (part, "joints", jname, "child"),
                f"link already has parent joint {children[j.child]}",
            )
        children[j.child] = jname
        if j.parent == j.child:
            add((part, "joints", jname, "child"), "a joint cannot connect a link to itself")
        lim = j.limit  # written limits in order, even a continuous joint's (URDF keeps them)
        if lim and lim.lower is not None and lim.upper is not None and lim.lower > lim.upper:
            add((part, "joints", jname, "limit", "upper"), f"must be >= lower ({lim.lower:g})")
    roots = root_links(links, children)
    if len(roots) != 1:
        add((part, "links"), f"exactly one root link expected, found {len(roots)}: {roots}")
        return
    reached = {roots[0]}
    below: dict[str, list[str]] = {}
    for j in joints.values():
        below.setdefault(j.parent, []).append(j.child)
    frontier = [roots[0]]  # one pass over the tree: linear in its size
    while frontier:
        for child in below.get(frontier.pop(), ()):
            if child not in reached:
                reached.add(child)
                frontier.append(child)
    orphans = sorted(set(links) - reached)
    if orphans:
        add((part, "joints"), f"links not connected to root {roots[0]!r}: {orphans}")


def _plugin_problems(spec: RobotSpec, all_joints: dict[str, Joint], add: Any) -> None:
    jsp = spec.arm.joint_state_publisher
    if jsp is not None:
        for i, jn in enumerate(jsp.joints):
            if jn not in all_joints:
                add(
                    ("arm", "joint_state_publisher", "joints", i),
                    f"unknown joint {jn!r}; known: {_names(all_joints)}",
                )
    if spec.arm.tool is not None and spec.arm.tool.link not in spec.arm.links:
        add(("arm", "tool", "link"), f"unknown arm link; known: {_names(spec.arm.links)}")
    dd = spec.mobile_base.diff_drive if spec.mobile_base else None
    if dd is not None:
        for role in ("left_joint", "right_joint"):
            jn = getattr(dd, role)
            if jn not in all_joints:
                add(
                    ("mobile_base", "diff_drive", role),
                    f"unknown joint; known: {_names(all_joints)}",
                )
        links = spec.all_links()
        if dd.robot_base_frame not in links:
            add(("mobile_base", "diff_drive", "robot_base_frame"), "unknown link")


def _names(d: Any) -> str:
    return ", ".join(sorted(d)) or "(none)"


def _unknown(what: str, name: object, known: Any, *, named: bool = False) -> str:
    """`unknown link; did you mean 'hand_link'? known: ...` (`named`: the name in the text)."""
    label = f"unknown {what} {name!r}" if named else f"unknown {what}"
    return f"{label}; {did_you_mean(name, known)}known: {_names(known)}"
