"""Pydantic models of the whole robot spec: parts, plugins, control, poses.

One YAML file holds every value of the robot (shapes, colours, masses, limits,
dynamics, plugins, gains, poses) so that nothing is typed twice. Links and joints
have their own modules (`spec.shapes`, `spec.joints`) and are re-exported here. Field
validation (types, finiteness, positivity, unknown keys) is pydantic's job;
cross-references (parents exist, one root, plugin joints exist) are checked in
`spec.semantics`. Both report through `SpecError` with file, line and path.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from pathlib import Path

from pydantic import Field, PrivateAttr

from armcli.defaults import DEFAULT_DT, MAX_DT
from armcli.spec.control import Hardware, Interface, JointControl, Ros2Control
from armcli.spec.graph import root_links
from armcli.spec.joint_types import JointType
from armcli.spec.joints import (
    Calibration,
    Dynamics,
    Joint,
    Limit,
    Mimic,
    SafetyController,
)
from armcli.spec.parts import Part, Placement
from armcli.spec.passthrough import PassthroughElement
from armcli.spec.sensors import Camera, Imu, Lidar, Noise, Sensor
from armcli.spec.shapes import (
    Box,
    Contact,
    Cylinder,
    Geometry,
    Inertia,
    Inertial,
    InlineMaterial,
    Link,
    Material,
    Mesh,
    Origin,
    Shape,
    Sphere,
)
from armcli.spec.types import (
    Name,
    NonNeg,
    Positive,
    Real,
    RobotName,
    Text,
    TimeStep,
    UrdfName,
    Vec3,
    _Model,
)

__all__ = [
    "Arm",
    "Box",
    "Calibration",
    "Camera",
    "Contact",
    "Control",
    "Cylinder",
    "DiffDrive",
    "Dynamics",
    "Gains",
    "Geometry",
    "Hardware",
    "Imu",
    "Inertia",
    "Inertial",
    "InlineMaterial",
    "Interface",
    "Joint",
    "JointControl",
    "JointPoseTrajectory",
    "JointStatePublisher",
    "JointType",
    "Lidar",
    "Limit",
    "Link",
    "Material",
    "Mesh",
    "Mimic",
    "MobileBase",
    "Mount",
    "Noise",
    "Origin",
    "Part",
    "Placement",
    "RobotSpec",
    "Ros2Control",
    "SafetyController",
    "Sensor",
    "Shape",
    "Sphere",
    "Tolerances",
    "Tool",
]


class DiffDrive(_Model):
    """gazebo_ros_diff_drive parameters; `simulate --cmd-vel` drives the robot with them."""

    update_rate: Positive = Field(description="plugin update rate [Hz]")
    left_joint: UrdfName = Field(description="left wheel joint name")
    right_joint: UrdfName = Field(description="right wheel joint name")
    wheel_separation: Positive = Field(description="distance between the wheels [m]")
    wheel_diameter: Positive = Field(description="wheel diameter [m]")
    max_wheel_torque: Positive = Field(20.0, description="largest wheel torque [N·m]")
    max_wheel_acceleration: NonNeg = Field(
        1.0,
        description="largest wheel rim acceleration [m/s²] (as gazebo_ros_diff_drive uses it); "
        "0: no limit, the plugin's own default",
    )
    publish_odom: bool = Field(True, description="publish the odometry topic")
    publish_odom_tf: bool = Field(True, description="publish the odom -> base transform")
    publish_wheel_tf: bool = Field(True, description="publish the wheel transforms")
    odometry_frame: UrdfName = Field("odom", description="odometry frame name")
    robot_base_frame: UrdfName = Field("base_footprint", description="frame the odometry moves")


class JointStatePublisher(_Model):
    """gazebo_ros_joint_state_publisher: publishes these joints at `update_rate` [Hz]."""

    update_rate: Positive = Field(description="publish rate [Hz]; also `simulate`'s output rate")
    joints: list[UrdfName] = Field(min_length=1, description="joints to publish")


class JointPoseTrajectory(_Model):
    """gazebo_ros_joint_pose_trajectory: follows /set_joint_trajectory at `update_rate` [Hz]."""

    update_rate: Positive = Field(description="rate the trajectory is applied at [Hz]")


class Tool(_Model):
    """The end-effector point: a fixed offset [m] in `link`'s frame (e.g. the hand tip)."""

    link: UrdfName = Field(description="link the tool point is fixed in")
    xyz: Vec3 = Field(
        (0.0, 0.0, 0.0), description="offset of the tool point in that link's frame [m]"
    )


class MobileBase(_Model):
    """The mobile base: its links and joints (one tree) and an optional diff-drive plugin."""

    links: dict[UrdfName, Link] = Field(description="links by name")
    joints: dict[UrdfName, Joint] = Field({}, description="joints by name (one tree)")
    diff_drive: DiffDrive | None = Field(None, description="differential-drive plugin")
    parts: list[Placement] = Field([], description="copies of reusable parts on the base")


class Arm(_Model):
    """The arm: its links and joints (one tree), its Gazebo plugins and the tool point."""

    links: dict[UrdfName, Link] = Field(min_length=1, description="links by name")
    joints: dict[UrdfName, Joint] = Field({}, description="joints by name (one tree)")
    joint_state_publisher: JointStatePublisher | None = Field(
        None, description="Gazebo joint-state publisher plugin"
    )
    joint_pose_trajectory: JointPoseTrajectory | None = Field(
        None, description="Gazebo joint pose-trajectory plugin (the course's)"
    )
    tool: Tool | None = Field(
        None, description="end-effector point reported by check, simulate, view and render"
    )
    parts: list[Placement] = Field([], description="copies of reusable parts on the arm")


class Mount(_Model):
    """The fixed joint that puts the arm's root link on the mobile base."""

    joint: UrdfName = Field(description="name of the fixed mount joint")
    parent: UrdfName = Field(description="base link the arm is mounted on")
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

    dt: TimeStep = Field(
        DEFAULT_DT, description=f"control and simulation time step [s], in (0, {MAX_DT:g}]"
    )
    gains: dict[UrdfName, Gains] = Field({}, description="PD gains per arm joint")
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

    name: RobotName = Field(description="robot name; also the ROS package prefix")
    materials: dict[UrdfName, Material] = Field({}, description="colours by name")
    mobile_base: MobileBase | None = Field(
        None, description="the mobile base, if the arm rides on one"
    )
    arm: Arm = Field(description="the arm")
    mount: Mount | None = Field(None, description="where the arm sits on the base")
    control: Control = Field(Control(), description="controller gains and time step")
    poses: dict[Name, dict[UrdfName, Real]] = Field(
        {}, description="named poses: joint name -> position [rad or m]"
    )
    parts: dict[Name, Part] = Field(
        {}, description="reusable groups of links and joints, placed under mobile_base/arm"
    )
    sensors: dict[Name, Sensor] = Field(
        {}, description="cameras, lidars and IMUs on links, by name"
    )
    ros2_control: Ros2Control | None = Field(
        None, description="ros2_control interfaces per joint (both ROS targets), hardware"
    )
    passthrough: list[PassthroughElement] = Field(
        [],
        description="URDF elements kept verbatim (what `armcli import` could not type)",
    )
    packages: dict[UrdfName, Text] = Field(
        {},
        description="where the ROS packages named by `package://` meshes are: NAME -> its "
        "directory (holding its package.xml), relative to this spec; `armcli import` writes "
        "it; `--package-dir` overrides",
    )
    _source: Path | None = PrivateAttr(None)

    @property
    def base_dir(self) -> Path:
        """The directory relative mesh paths start from: the spec file's (else the cwd)."""
        return self._source.parent if self._source is not None else Path(".")

    @property
    def source_file(self) -> str:
        """The spec file's name for messages ("<spec>" when built in memory)."""
        return str(self._source) if self._source is not None else "<spec>"

    def package_dirs(self) -> dict[str, Path]:
        """`packages` with each directory from the spec file's directory."""
        return {name: self.base_dir / rel for name, rel in self.packages.items()}

    def with_source(self, path: Path) -> RobotSpec:
        """This spec, remembering the file it was read from (for relative mesh paths)."""
        self._source = path
        return self

    # -- derived views used by writers, checks and the simulator ----------------
    def all_links(self) -> dict[str, Link]:
        """Links of the base and the arm by name (names are unique across parts)."""
        out = dict(self.mobile_base.links) if self.mobile_base else {}
        out.update(self.arm.links)
        return out

    def parts_placements(self) -> list[Placement]:
        """Every placement of a reusable part, arm and base."""
        base = self.mobile_base.parts if self.mobile_base is not None else []
        return [*self.arm.parts, *base]

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
    """Joints breadth-first from `root`, siblings in spec order (linear in the tree's size)."""
    below: dict[str, list[tuple[str, Joint]]] = {}
    for name, j in joints.items():
        below.setdefault(j.parent, []).append((name, j))
    frontier, seen = deque([root]), {root}
    while frontier:
        for name, j in below.get(frontier.popleft(), ()):
            yield name, j
            if j.child not in seen:  # a link with two parents is reported, not looped over
                seen.add(j.child)
                frontier.append(j.child)
