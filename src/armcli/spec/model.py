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
from armcli.spec.graph import root_links


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

    rgba: tuple[Unit, Unit, Unit, Unit] = Field(
        description="red, green, blue, alpha in [0, 1] (RViz colour)"
    )
    gazebo: str = Field(
        pattern=r"^[A-Za-z0-9_/]+$",
        max_length=64,
        description="Gazebo classic material name, e.g. Gazebo/Orange",
    )


class Origin(_Model):
    """A frame offset: translation `xyz` [m] and roll-pitch-yaw `rpy` [rad], as URDF's <origin>."""

    xyz: Vec3 = Field((0.0, 0.0, 0.0), description="translation [m]")
    rpy: Vec3 = Field(
        (0.0, 0.0, 0.0), description="roll, pitch, yaw [rad], applied about fixed x, y, z"
    )


class Box(_Model):
    """A box with edge lengths `size` [m] along x, y and z."""

    size: tuple[Positive, Positive, Positive] = Field(description="edge lengths along x, y, z [m]")


class Cylinder(_Model):
    """A cylinder of `radius` and `length` [m], its axis along z."""

    radius: Positive = Field(description="radius [m]")
    length: Positive = Field(description="length along the z axis [m]")


class Sphere(_Model):
    """A sphere of `radius` [m]."""

    radius: Positive = Field(description="radius [m]")


class Geometry(_Model):
    """Exactly one primitive shape, as in URDF's <geometry>."""

    box: Box | None = Field(None, description="a box")
    cylinder: Cylinder | None = Field(None, description="a cylinder")
    sphere: Sphere | None = Field(None, description="a sphere")

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

    mu1: NonNeg = Field(description="Gazebo friction coefficient along the first direction [-]")
    mu2: NonNeg = Field(description="Gazebo friction coefficient along the second direction [-]")


class Link(_Model):
    """A solid primitive: visual, collision and inertia all come from the same shape.

    `origin` places the shape (and so its centre of mass) in the link frame.
    A link without geometry is an empty frame such as `base_footprint`.
    """

    geometry: Geometry | None = Field(
        None,
        description="the solid's shape (visual, collision and inertia); none for an empty frame",
    )
    origin: Origin = Field(
        Origin(), description="pose of the shape and its centre of mass in the link frame"
    )
    material: Name | None = Field(None, description="name of an entry of `materials`")
    mass: Positive | None = Field(
        None, description="mass [kg]; the inertia tensor follows from the shape"
    )
    contact: Contact | None = Field(None, description="Gazebo surface friction")

    @model_validator(mode="after")
    def _solid(self) -> Link:
        if self.geometry is not None and self.mass is None:
            raise ValueError("a link with geometry needs a mass")
        if self.geometry is None and (self.mass is not None or self.material is not None):
            raise ValueError("mass/material given without geometry")
        return self


class Limit(_Model):
    """Joint limits: `lower`/`upper` [rad or m], `effort` [N·m or N], `velocity` [rad/s or m/s]."""

    lower: Real = Field(description="lower position limit [rad or m]")
    upper: Real = Field(description="upper position limit [rad or m], >= lower")
    effort: Positive = Field(description="largest motor torque or force [N·m or N]")
    velocity: Positive = Field(description="largest speed [rad/s or m/s]")


class Dynamics(_Model):
    """Joint `friction` [N·m or N] and viscous `damping` [N·m·s/rad or N·s/m]."""

    friction: NonNeg = Field(
        0.0, description="Coulomb (static) friction torque or force [N·m or N]"
    )
    damping: NonNeg = Field(0.0, description="viscous damping [N·m·s/rad or N·s/m]")


JointType = Literal["revolute", "continuous", "prismatic", "fixed"]


class Joint(_Model):
    """A URDF joint from `parent` to `child`; revolute and prismatic joints need a `limit`.

    `origin` places the joint frame in the parent link's frame; `axis` is a non-zero vector
    in the joint frame.
    """

    type: JointType = Field(description="revolute, continuous, prismatic or fixed")
    parent: Name = Field(description="parent link name")
    child: Name = Field(description="child link name")
    origin: Origin = Field(Origin(), description="pose of the joint frame in the parent link frame")
    axis: Vec3 = Field(
        (0.0, 0.0, 1.0),
        description="rotation or translation axis in the joint frame (non-zero) [-]",
    )
    limit: Limit | None = Field(
        None, description="limits; required for revolute and prismatic joints"
    )
    dynamics: Dynamics | None = Field(None, description="friction and damping")

    @model_validator(mode="after")
    def _limits(self) -> Joint:
        if self.type in ("revolute", "prismatic") and self.limit is None:
            raise ValueError(f"a {self.type} joint needs a limit")
        if self.type != "fixed" and math.fsum(a * a for a in self.axis) < 1e-12:
            raise ValueError("axis must be non-zero")
        return self


class DiffDrive(_Model):
    """gazebo_ros_diff_drive parameters."""

    update_rate: Positive = Field(description="plugin update rate [Hz]")
    left_joint: Name = Field(description="left wheel joint name")
    right_joint: Name = Field(description="right wheel joint name")
    wheel_separation: Positive = Field(description="distance between the wheels [m]")
    wheel_diameter: Positive = Field(description="wheel diameter [m]")
    max_wheel_torque: Positive = Field(20.0, description="largest wheel torque [N·m]")
    max_wheel_acceleration: Positive = Field(1.0, description="largest wheel acceleration [rad/s²]")
    publish_odom: bool = Field(True, description="publish the odometry topic")
    publish_odom_tf: bool = Field(True, description="publish the odom -> base transform")
    publish_wheel_tf: bool = Field(True, description="publish the wheel transforms")
    odometry_frame: Name = Field("odom", description="odometry frame name")
    robot_base_frame: Name = Field("base_footprint", description="frame the odometry moves")


class JointStatePublisher(_Model):
    """gazebo_ros_joint_state_publisher: publishes these joints at `update_rate` [Hz]."""

    update_rate: Positive = Field(description="publish rate [Hz]; also `simulate`'s output rate")
    joints: list[Name] = Field(min_length=1, description="joints to publish")


class JointPoseTrajectory(_Model):
    """gazebo_ros_joint_pose_trajectory: follows /set_joint_trajectory at `update_rate` [Hz]."""

    update_rate: Positive = Field(description="rate the trajectory is applied at [Hz]")


class Tool(_Model):
    """The end-effector point: a fixed offset [m] in `link`'s frame (e.g. the hand tip)."""

    link: Name = Field(description="link the tool point is fixed in")
    xyz: Vec3 = Field(
        (0.0, 0.0, 0.0), description="offset of the tool point in that link's frame [m]"
    )


class MobileBase(_Model):
    """The mobile base: its links and joints (one tree) and an optional diff-drive plugin."""

    links: dict[Name, Link] = Field(description="links by name")
    joints: dict[Name, Joint] = Field({}, description="joints by name (one tree)")
    diff_drive: DiffDrive | None = Field(None, description="differential-drive plugin")


class Arm(_Model):
    """The arm: its links and joints (one tree), its Gazebo plugins and the tool point."""

    links: dict[Name, Link] = Field(min_length=1, description="links by name")
    joints: dict[Name, Joint] = Field({}, description="joints by name (one tree)")
    joint_state_publisher: JointStatePublisher | None = Field(
        None, description="Gazebo joint-state publisher plugin"
    )
    joint_pose_trajectory: JointPoseTrajectory | None = Field(
        None, description="Gazebo joint pose-trajectory plugin (the course's)"
    )
    tool: Tool | None = Field(
        None, description="end-effector point reported by check, simulate, view and render"
    )


class Mount(_Model):
    """The fixed joint that puts the arm's root link on the mobile base."""

    joint: Name = Field(description="name of the fixed mount joint")
    parent: Name = Field(description="base link the arm is mounted on")
    origin: Origin = Field(Origin(), description="pose of the arm root in that link's frame")


class Gains(_Model):
    """PD(+I) gains of one joint: torque = kp*(q_ref - q) + kd*(v_ref - v) [+ ki*integral]."""

    kp: NonNeg = Field(description="proportional gain [N·m/rad or N/m]")
    kd: NonNeg = Field(description="derivative gain [N·m·s/rad or N·s/m]")
    ki: NonNeg = Field(
        0.0,
        description="integral gain [N·m/(rad·s) or N/(m·s)]; ROS only (simulate refuses it)",
    )


class Tolerances(_Model):
    """Trajectory-following limits for the Jazzy JointTrajectoryController (`constraints`).

    Defaults: `stopped_velocity_tolerance` and `trajectory` are the controller's own
    defaults (0.01 rad/s; 0 = not checked: a PD loop under gravity lags its reference);
    `goal_time` is MoveIt's default goal-duration margin; `goal` is 0.05 rad because a
    P(D) loop without integral action settles off the goal by gravity torque / Kp.
    """

    goal_time: NonNeg = Field(
        0.5, description="extra time allowed to reach the goal [s]; 0 = unlimited"
    )
    stopped_velocity_tolerance: NonNeg = Field(
        0.01, description="speed under which a joint counts as stopped [rad/s or m/s]"
    )
    goal: NonNeg = Field(
        0.05, description="position error allowed at the goal [rad or m]; 0 = not checked"
    )
    trajectory: NonNeg = Field(
        0.0, description="position error allowed along the way [rad or m]; 0 = not checked"
    )


class Control(_Model):
    """How the arm is controlled and simulated.

    `dt` is the simulation step [s], `gains` the PD gains per arm joint,
    `controller_update_rate` the ros2_control rate [Hz].
    """

    dt: Positive = Field(DEFAULT_DT, description="control and simulation time step [s]")
    gains: dict[Name, Gains] = Field({}, description="PD gains per arm joint")
    controller_update_rate: Positive = Field(
        100.0, description="ros2_control controller manager rate [Hz]"
    )
    gravity_compensation: bool = Field(
        False, description="add the gravity torque g(q) to the PD torque"
    )
    tolerances: Tolerances = Field(
        Tolerances(), description="JointTrajectoryController constraints (Jazzy target)"
    )


class RobotSpec(_Model):
    """The whole robot: base, arm, how they are mounted, and how the arm is controlled."""

    name: Name = Field(description="robot name; also the ROS package prefix")
    materials: dict[Name, Material] = Field({}, description="colours by name")
    mobile_base: MobileBase | None = Field(
        None, description="the mobile base, if the arm rides on one"
    )
    arm: Arm = Field(description="the arm")
    mount: Mount | None = Field(None, description="where the arm sits on the base")
    control: Control = Field(Control(), description="controller gains and time step")
    poses: dict[Name, dict[Name, Real]] = Field(
        {}, description="named poses: joint name -> position [rad or m]"
    )

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
        if self.mounted_base() is not None:
            out[self.mount_joint_name()] = self.mount_joint()
        return out

    def mounted_base(self) -> MobileBase | None:
        """The mobile base the arm is mounted on; None for an arm alone.

        A valid spec has both a base and a mount or neither; this is the one test of it.
        """
        return self.mobile_base if self.mount is not None else None

    def mount_joint_name(self) -> str:
        """The name of the fixed joint from the base to the arm root; needs a mount."""
        assert self.mount is not None
        return self.mount.joint

    def arm_root(self) -> str:
        """The arm link that is no arm joint's child (a valid spec has exactly one)."""
        return root_links(self.arm.links, (j.child for j in self.arm.joints.values()))[0]

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
