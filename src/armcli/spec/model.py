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
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    model_validator,
)

from armcli.defaults import DEFAULT_DT
from armcli.spec.expr import eval_expr


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
    """A frame offset: translation `xyz` [m] and roll-pitch-yaw `rpy` [rad], as URDF's <origin>."""

    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)


class Box(_Model):
    """A box with edge lengths `size` [m] along x, y and z."""

    size: tuple[Positive, Positive, Positive]


class Cylinder(_Model):
    """A cylinder of `radius` and `length` [m], its axis along z."""

    radius: Positive
    length: Positive


class Sphere(_Model):
    """A sphere of `radius` [m]."""

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
        """Which primitive is given: "box", "cylinder" or "sphere"."""
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
    """Joint limits: `lower`/`upper` [rad or m], `effort` [N·m or N], `velocity` [rad/s or m/s]."""

    lower: Real
    upper: Real
    effort: Positive
    velocity: Positive


class Dynamics(_Model):
    """Joint `friction` [N·m or N] and viscous `damping` [N·m·s/rad or N·s/m]."""

    friction: NonNeg = 0.0
    damping: NonNeg = 0.0


JointType = Literal["revolute", "continuous", "prismatic", "fixed"]


class Joint(_Model):
    """A URDF joint from `parent` to `child`; revolute and prismatic joints need a `limit`.

    `origin` places the joint frame in the parent link's frame; `axis` is a non-zero vector
    in the joint frame.
    """

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
    """The mobile base: its links and joints (one tree) and an optional diff-drive plugin."""

    links: dict[Name, Link]
    joints: dict[Name, Joint] = {}
    diff_drive: DiffDrive | None = None


class Arm(_Model):
    """The arm: its links and joints (one tree), its Gazebo plugins and the tool point."""

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
    """How the arm is controlled and simulated.

    `dt` is the simulation step [s], `gains` the PD gains per arm joint,
    `controller_update_rate` the ros2_control rate [Hz].
    """

    dt: Positive = DEFAULT_DT
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
        """Links of the base and the arm by name (names are unique across parts)."""
        out = dict(self.mobile_base.links) if self.mobile_base else {}
        out.update(self.arm.links)
        return out

    def all_joints(self) -> dict[str, Joint]:
        """Joints of the base and the arm by name, plus the mount joint with a base."""
        out = dict(self.mobile_base.joints) if self.mobile_base else {}
        out.update(self.arm.joints)
        if self.mount is not None and self.mobile_base is not None:
            out[self.mount.joint] = self.mount_joint()
        return out

    def arm_root(self) -> str:
        """The arm link that is no arm joint's child (a valid spec has exactly one)."""
        children = {j.child for j in self.arm.joints.values()}
        roots = [name for name in self.arm.links if name not in children]
        return roots[0]

    def mount_joint(self) -> Joint:
        """The mount as the fixed `Joint` from the base to the arm root; needs a mount."""
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
