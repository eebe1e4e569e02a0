"""Pydantic models of the robot spec and `load_spec()`.

One YAML file holds every value of the course project (sizes, colours, masses,
limits, dynamics, plugins, gains, poses) so that nothing is typed twice. Field
validation (types, finiteness, positivity, unknown keys) is pydantic's job;
cross-references (parents exist, one root, plugin joints exist) are checked in
`_semantic_problems`. Both report through `SpecError` with file, line and path.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    model_validator,
)

from armcli.errors import Problem, SpecError
from armcli.expr import eval_expr
from armcli.yamlio import YamlDoc, dotted, load_yaml, loads_yaml


def _number(v: Any) -> Any:
    """Accept numbers and simple expressions of pi; reject bools and non-finite values."""
    if isinstance(v, bool):
        raise ValueError("expected a number, got a boolean")
    if isinstance(v, str):
        return eval_expr(v)
    return v


def _finite(v: float) -> float:
    if not math.isfinite(v):
        raise ValueError("must be a finite number")
    return v


Real = Annotated[float, BeforeValidator(_number), AfterValidator(_finite)]
Positive = Annotated[Real, Field(gt=0)]
NonNeg = Annotated[Real, Field(ge=0)]
Unit = Annotated[Real, Field(ge=0, le=1)]
Vec3 = tuple[Real, Real, Real]
Name = Annotated[str, Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]*$", max_length=64)]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Material(_Model):
    """A colour for RViz (`rgba`) and its Gazebo classic material name."""

    rgba: tuple[Unit, Unit, Unit, Unit]
    gazebo: str = Field(pattern=r"^[A-Za-z0-9_/]+$", max_length=64)


class Origin(_Model):
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)


class Box(_Model):
    size: tuple[Positive, Positive, Positive]


class Cylinder(_Model):
    radius: Positive
    length: Positive


class Sphere(_Model):
    radius: Positive


class Geometry(_Model):
    """Exactly one primitive shape, as in URDF's <geometry>."""

    box: Box | None = None
    cylinder: Cylinder | None = None
    sphere: Sphere | None = None

    @model_validator(mode="after")
    def _exactly_one(self) -> Geometry:
        n = sum(s is not None for s in (self.box, self.cylinder, self.sphere))
        if n != 1:
            raise ValueError("give exactly one of box, cylinder, sphere")
        return self

    @property
    def kind(self) -> str:
        return "box" if self.box else "cylinder" if self.cylinder else "sphere"


class Contact(_Model):
    """Gazebo surface friction coefficients for a link."""

    mu1: NonNeg
    mu2: NonNeg


class Link(_Model):
    """A solid primitive: visual, collision and inertia all come from the same shape.

    `origin` places the shape (and so its centre of mass) in the link frame.
    A link without geometry is an empty frame such as `base_footprint`.
    """

    geometry: Geometry | None = None
    origin: Origin = Origin()
    material: Name | None = None
    mass: Positive | None = None
    contact: Contact | None = None

    @model_validator(mode="after")
    def _solid(self) -> Link:
        if self.geometry is not None and self.mass is None:
            raise ValueError("a link with geometry needs a mass")
        if self.geometry is None and (self.mass is not None or self.material is not None):
            raise ValueError("mass/material given without geometry")
        return self


class Limit(_Model):
    lower: Real
    upper: Real
    effort: Positive
    velocity: Positive


class Dynamics(_Model):
    friction: NonNeg = 0.0
    damping: NonNeg = 0.0


JointType = Literal["revolute", "continuous", "prismatic", "fixed"]


class Joint(_Model):
    type: JointType
    parent: Name
    child: Name
    origin: Origin = Origin()
    axis: Vec3 = (0.0, 0.0, 1.0)
    limit: Limit | None = None
    dynamics: Dynamics | None = None

    @model_validator(mode="after")
    def _limits(self) -> Joint:
        if self.type in ("revolute", "prismatic") and self.limit is None:
            raise ValueError(f"a {self.type} joint needs a limit")
        if self.type != "fixed" and math.fsum(a * a for a in self.axis) < 1e-12:
            raise ValueError("axis must be non-zero")
        return self


class DiffDrive(_Model):
    """gazebo_ros_diff_drive parameters."""

    update_rate: Positive
    left_joint: Name
    right_joint: Name
    wheel_separation: Positive
    wheel_diameter: Positive
    max_wheel_torque: Positive = 20.0
    max_wheel_acceleration: Positive = 1.0
    publish_odom: bool = True
    publish_odom_tf: bool = True
    publish_wheel_tf: bool = True
    odometry_frame: Name = "odom"
    robot_base_frame: Name = "base_footprint"


class JointStatePublisher(_Model):
    """gazebo_ros_joint_state_publisher: publishes these joints at `update_rate` [Hz]."""

    update_rate: Positive
    joints: list[Name] = Field(min_length=1)


class JointPoseTrajectory(_Model):
    """gazebo_ros_joint_pose_trajectory: follows /set_joint_trajectory at `update_rate` [Hz]."""

    update_rate: Positive


class Tool(_Model):
    """The end-effector point: a fixed offset [m] in `link`'s frame (e.g. the hand tip)."""

    link: Name
    xyz: Vec3 = (0.0, 0.0, 0.0)


class MobileBase(_Model):
    links: dict[Name, Link]
    joints: dict[Name, Joint] = {}
    diff_drive: DiffDrive | None = None


class Arm(_Model):
    links: dict[Name, Link] = Field(min_length=1)
    joints: dict[Name, Joint] = {}
    joint_state_publisher: JointStatePublisher | None = None
    joint_pose_trajectory: JointPoseTrajectory | None = None
    tool: Tool | None = None


class Mount(_Model):
    """The fixed joint that puts the arm's root link on the mobile base."""

    joint: Name
    parent: Name
    origin: Origin = Origin()


class Gains(_Model):
    """PD(+I) gains of one joint: torque = kp*(q_ref - q) + kd*(v_ref - v) [+ ki*integral]."""

    kp: NonNeg
    kd: NonNeg
    ki: NonNeg = 0.0


class Control(_Model):
    dt: Positive = 0.001
    gains: dict[Name, Gains] = {}
    controller_update_rate: Positive = 100.0
    gravity_compensation: bool = False


class RobotSpec(_Model):
    """The whole robot: base, arm, how they are mounted, and how the arm is controlled."""

    name: Name
    materials: dict[Name, Material] = {}
    mobile_base: MobileBase | None = None
    arm: Arm
    mount: Mount | None = None
    control: Control = Control()
    poses: dict[Name, dict[Name, Real]] = {}

    # -- derived views used by writers, checks and the simulator ----------------
    def all_links(self) -> dict[str, Link]:
        out = dict(self.mobile_base.links) if self.mobile_base else {}
        out.update(self.arm.links)
        return out

    def all_joints(self) -> dict[str, Joint]:
        out = dict(self.mobile_base.joints) if self.mobile_base else {}
        out.update(self.arm.joints)
        if self.mount is not None and self.mobile_base is not None:
            out[self.mount.joint] = self.mount_joint()
        return out

    def arm_root(self) -> str:
        children = {j.child for j in self.arm.joints.values()}
        roots = [name for name in self.arm.links if name not in children]
        return roots[0]

    def mount_joint(self) -> Joint:
        assert self.mount is not None
        return Joint(
            type="fixed", parent=self.mount.parent, child=self.arm_root(), origin=self.mount.origin
        )

    def movable_arm_joints(self) -> list[str]:
        """Arm joints that move, in tree order from the arm root."""
        return [n for n, j in _tree_order(self.arm.joints, self.arm_root()) if j.type != "fixed"]

    def pose(self, name: str) -> dict[str, float]:
        """Named pose with unspecified joints at 0."""
        base = {j: 0.0 for j in self.movable_arm_joints()}
        base.update(self.poses[name])
        return base


def _tree_order(joints: dict[str, Joint], root: str) -> Iterator[tuple[str, Joint]]:
    frontier = [root]
    while frontier:
        link = frontier.pop(0)
        for name, j in joints.items():
            if j.parent == link:
                yield name, j
                frontier.append(j.child)


# -- semantic validation ---------------------------------------------------------


def _semantic_problems(spec: RobotSpec) -> list[Problem]:
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
            if link.material is not None and link.material not in spec.materials:
                add(
                    (part, "links", lname, "material"),
                    f"unknown material {link.material!r}; known: {_names(spec.materials)}",
                )

    arm_movable = set(spec.movable_arm_joints()) if not out else set()
    all_joints = {**base_joints, **spec.arm.joints}
    _plugin_problems(spec, all_joints, add)
    if spec.mount is not None:
        if spec.mobile_base is None:
            add(("mount",), "a mount needs a mobile_base")
        elif spec.mount.parent not in base_links:
            add(("mount", "parent"), f"unknown link; known: {_names(base_links)}")
        if spec.mount.joint in all_joints:
            add(("mount", "joint"), "joint name already used")
    elif spec.mobile_base is not None:
        add(("mount",), "a mobile_base needs a mount joint for the arm")

    for jname in spec.control.gains:
        if jname not in spec.arm.joints:
            add(("control", "gains", jname), f"unknown arm joint; known: {_names(spec.arm.joints)}")
    for pname, pose in spec.poses.items():
        for jname, value in pose.items():
            j = spec.arm.joints.get(jname)
            if j is None or (arm_movable and jname not in arm_movable):
                add(("poses", pname, jname), f"unknown arm joint; known: {_names(spec.arm.joints)}")
            elif (
                j.limit is not None
                and j.type != "continuous"
                and j.limit.lower <= j.limit.upper
                and not (j.limit.lower - 1e-12 <= value <= j.limit.upper + 1e-12)
            ):
                add(
                    ("poses", pname, jname),
                    f"{value:g} is outside the joint limits [{j.limit.lower:g}, {j.limit.upper:g}]",
                )
    return out


def _tree_problems(part: str, links: dict[str, Link], joints: dict[str, Joint], add: Any) -> None:
    children: dict[str, str] = {}
    for jname, j in joints.items():
        for role in ("parent", "child"):
            if getattr(j, role) not in links:
                add((part, "joints", jname, role), f"unknown link; known: {_names(links)}")
        if j.child in children:
            add(
                (part, "joints", jname, "child"),
                f"link already has parent joint {children[j.child]}",
            )
        children[j.child] = jname
        if j.parent == j.child:
            add((part, "joints", jname, "child"), "a joint cannot connect a link to itself")
        if j.limit is not None and j.limit.lower > j.limit.upper:
            add(
                (part, "joints", jname, "limit", "upper"),
                f"must be >= lower ({j.limit.lower:g})",
            )
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        add((part, "links"), f"exactly one root link expected, found {len(roots)}: {roots}")
        return
    reached = {roots[0]}
    for _ in range(len(links)):
        reached |= {j.child for j in joints.values() if j.parent in reached}
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


# -- loading -----------------------------------------------------------------------


def _pydantic_problems(exc: ValidationError, doc: YamlDoc) -> list[Problem]:
    out = []
    for err in exc.errors():
        loc = tuple(p for p in err["loc"] if not (isinstance(p, str) and p[:1].isupper()))
        msg = err["msg"]
        if msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        out.append(Problem(dotted(loc), msg, doc.line_of(loc)))
    return out


def spec_from_doc(doc: YamlDoc) -> RobotSpec:
    """Validate parsed YAML into a RobotSpec or raise SpecError listing every problem."""
    if not isinstance(doc.data, dict):
        raise SpecError(doc.source, [Problem("", "a spec must be a YAML mapping", 1)])
    try:
        spec = RobotSpec.model_validate(doc.data)
    except ValidationError as exc:
        raise SpecError(doc.source, _pydantic_problems(exc, doc)) from None
    problems = _semantic_problems(spec)
    if problems:
        lines = [Problem(p.field, p.message, doc.line_of(_split(p.field))) for p in problems]
        raise SpecError(doc.source, lines)
    return spec


def _split(field: str) -> tuple[str | int, ...]:
    out: list[str | int] = []
    for part in field.replace("[", ".[").split("."):
        if part.startswith("["):
            out.append(int(part[1:-1]))
        elif part:
            out.append(part)
    return tuple(out)


def load_spec(path: str | Path) -> RobotSpec:
    """Read, parse and validate a spec file."""
    return spec_from_doc(load_yaml(path))


def loads_spec(text: str, source: str = "<string>") -> RobotSpec:
    return spec_from_doc(loads_yaml(text, source))


from armcli.defaults import DEFAULT_SPEC  # noqa: E402, F401  (re-export)
