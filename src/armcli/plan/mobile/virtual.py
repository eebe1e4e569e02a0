"""A mobile robot as its base planner sees it: the robot on a virtual planar joint in a room.

As MoveIt's `virtual_joint` of type planar, the robot's root link is put on three virtual
joints (x, y along the floor, yaw about the vertical), so one planning robot (the same
loader, `plan.robot.load_plan_robot`) and one collision checker (`plan.collision`) hold
the base pose and the arm together: the scene's objects stay where the scene file puts
them (its `world` frame is the floor's), and the base's own collision shapes, wheels and
all, are checked against them as the arm's are. The floor is a slab FLOOR_GAP below
z = 0, so wheels standing on the floor are clear of it and an arm reaching into it is
not. Planned values are `x = (x, y, yaw, arm joints...)`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from lxml import etree
from numpy.typing import ArrayLike

from armcli.analysis.stance import NoStance, Stance, stance_of
from armcli.errors import InputError
from armcli.io.scene import Scene, SceneObject, Shape, load_scene
from armcli.plan.collision import CollisionChecker
from armcli.plan.mobile.planar import PlanarArm, planar_arm
from armcli.plan.robot import MOVABLE, PlanRobot, load_plan_robot
from armcli.plan.srdf import allowed_pairs
from armcli.robot.file import floating_of
from armcli.robot.tool import tool_point
from armcli.urdf.doc import Joint, Urdf
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.read import parse_urdf
from armcli.urdf.source import RobotFile

BASE_JOINTS = ("armcli_base_x", "armcli_base_y", "armcli_base_yaw")
_VIRTUAL_LINKS = ("armcli_world", "armcli_base_x_link", "armcli_base_y_link")
ROOM = 1000.0  # [m] the virtual joints' range: the floor is as large as a scene makes it
FLOOR = "floor"  # the slab's id in collision reports
FLOOR_GAP = 0.001  # [m] the floor's top below z = 0
FLOOR_SIZE = (2 * ROOM, 2 * ROOM, 0.1)  # [m]


@dataclass(frozen=True)
class MobileRobot:
    """A robot on its virtual planar joint, its arm, the scene and what judges a pose."""

    robot: PlanRobot  # planned joints: BASE_JOINTS, then `arm`
    arm: tuple[str, ...]  # the joints between the root and the tool point
    checker: CollisionChecker  # the scene's objects and the floor, in the world frame
    scene: Scene  # the user's objects (without the floor)
    stance: Stance | None  # None: no support polygon (no wheels on the ground)
    no_stance: str  # why, when `stance` is None
    planar: PlanarArm | None  # the closed form, when the arm's reach is planar
    robot_file: RobotFile
    world: Scene  # the scene's objects and the floor: what the checker was built with
    disabled: tuple[tuple[str, str], ...]  # link pairs never checked (the collision matrix)

    def x(self, base: ArrayLike, q: ArrayLike) -> np.ndarray:
        """Planned values: the base pose (x, y, yaw) and the arm's joints."""
        return np.concatenate([np.asarray(base, dtype=float), np.asarray(q, dtype=float)])

    def arm_robot(self, base: ArrayLike = (0.0, 0.0, 0.0)) -> PlanRobot:
        """The planning robot with the base held at `base` (x, y, yaw): the arm's joints planned."""
        r, n = self.robot, len(BASE_JOINTS)
        b = np.asarray(base, dtype=float)
        held = {**r.held, **{j: float(v) for j, v in zip(BASE_JOINTS, b, strict=True)}}
        return replace(r, joints=r.joints[n:], acceleration=r.acceleration[n:], held=held)

    @property
    def base_links(self) -> tuple[str, ...]:
        """Links no arm joint moves: the base and whatever is fixed to it."""
        moved = _moved_links(self.robot.urdf, set(self.arm))
        return tuple(
            lk.name
            for lk in self.robot.urdf.links
            if lk.name not in moved and lk.name not in _VIRTUAL_LINKS
        )


def _moved_links(urdf: Urdf, joints: set[str]) -> set[str]:
    """Links below any of `joints`."""
    children: dict[str, list[str]] = {}
    for j in urdf.joints:
        children.setdefault(j.parent or "", []).append(j.child or "")
    out: set[str] = set()
    stack = [j.child or "" for j in urdf.joints if j.name in joints]
    while stack:
        link = stack.pop()
        if link not in out:
            out.add(link)
            stack += children.get(link, [])
    return out


def with_planar_base(urdf: Urdf) -> Urdf:
    """The document with its root link on the virtual joints (an XML edit, then parsed)."""
    taken = {lk.name for lk in urdf.links} | {j.name for j in urdf.joints}
    clash = sorted(taken & {*BASE_JOINTS, *_VIRTUAL_LINKS})
    if clash:
        raise InputError(
            f"the robot already has a link or joint called {clash[0]!r}, a name "
            "armcli's virtual base joint uses",
            file=urdf.source,
        )
    children = {j.child for j in urdf.joints}
    roots = [lk.name for lk in urdf.links if lk.name not in children]
    if len(roots) != 1:
        raise InputError("the robot needs exactly one root link to stand on", file=urdf.source)
    root = etree.fromstring(urdf.text, etree.XMLParser(resolve_entities=False))
    for name in _VIRTUAL_LINKS:
        etree.SubElement(root, "link", name=name)
    chain = [*_VIRTUAL_LINKS, roots[0]]
    kinds = (("prismatic", "1 0 0"), ("prismatic", "0 1 0"), ("continuous", "0 0 1"))
    for k, (name, (kind, axis)) in enumerate(zip(BASE_JOINTS, kinds, strict=True)):
        joint = etree.SubElement(root, "joint", name=name, type=kind)
        etree.SubElement(joint, "parent", link=chain[k])
        etree.SubElement(joint, "child", link=chain[k + 1])
        etree.SubElement(joint, "axis", xyz=axis)
        if kind == "prismatic":
            etree.SubElement(
                joint, "limit", lower=repr(-ROOM), upper=repr(ROOM), effort="0", velocity="0"
            )
    return parse_urdf(etree.tostring(root), urdf.source)


def tool_chain(urdf: Urdf, tool_link: str) -> tuple[str, ...]:
    """The movable joints from the root to the tool link, root first (mimic followers out)."""
    by_child: dict[str | None, Joint] = {j.child: j for j in urdf.joints}
    out = []
    link = tool_link
    while link in by_child:
        j = by_child[link]
        if j.type in MOVABLE and j.mimic is None:
            out.append(j.name)
        link = j.parent or ""
    return tuple(reversed(out))


def floor_object() -> SceneObject:
    """The floor: a slab whose top is FLOOR_GAP below z = 0."""
    T = np.eye(4)
    T[2, 3] = -FLOOR_GAP - FLOOR_SIZE[2] / 2
    return SceneObject(FLOOR, "", (Shape("box", FLOOR_SIZE, T),))


def load_mobile(
    robot_file: RobotFile, *, scene: Path | None = None, search: MeshSearch | None = None
) -> MobileRobot:
    """The robot of `robot_file` on its virtual planar joint among `scene`'s objects."""
    urdf, spec = robot_file.robot, robot_file.spec
    wrapped = with_planar_base(urdf)
    virtual_file = RobotFile(robot_file.path, (wrapped,), spec)
    tool = tool_point(urdf, spec)
    arm = tool_chain(urdf, tool.link) if tool is not None else ()
    if not arm:
        raise InputError("no movable joint moves the tool point", file=urdf.source)
    robot = load_plan_robot(virtual_file, joints=(*BASE_JOINTS, *arm), search=search)
    robot = replace(robot, mobile=False)  # the floor slab below stands for the ground plane
    links = [lk.name for lk in urdf.links]
    objects = load_scene(scene, links) if scene is not None else Scene()
    world = Scene((*objects.objects, floor_object()), objects.source)
    disabled = allowed_pairs(robot_file, None, search)
    checker = CollisionChecker(robot, world, disabled)
    candidates = set(spec.mobile_base.links) if spec is not None and spec.mobile_base else None
    standing = stance_of(urdf, candidates=candidates, floating=floating_of(robot_file, urdf))
    stance = None if isinstance(standing, NoStance) else standing
    planar = planar_arm(robot, arm)
    return MobileRobot(
        robot,
        arm,
        checker,
        objects,
        stance,
        standing.reason if isinstance(standing, NoStance) else "",
        planar,
        robot_file,
        world,
        tuple(disabled),
    )
