"""The typed view of one URDF document that `urdf.read` builds and the checks read.

Frozen dataclasses with the source line of every element, so findings can point
at the line; numbers that did not parse are kept as `NumberProblem`s.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal

from armcli.spec.joint_types import JOINT_DOF
from armcli.xacro.lines import Origin

Vec3 = tuple[float, float, float]
ZERO3: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class NumberProblem:
    """A numeric attribute that is missing, unparsable, non-finite or of the wrong length."""

    kind: Literal["missing", "not-a-number", "non-finite", "length"]
    where: str  # e.g. "link base_link: inertial/mass@value"
    text: str
    line: int | None


@dataclass(frozen=True)
class Pose:
    """An <origin>: `xyz` [m] and `rpy` [rad], with its source line."""

    xyz: Vec3 = ZERO3
    rpy: Vec3 = ZERO3
    line: int | None = None


@dataclass(frozen=True)
class Geometry:
    """kind is box/cylinder/sphere/mesh (or the unknown tag); dims [m] as URDF orders them."""

    kind: str
    dims: tuple[float, ...] | None  # box (x, y, z); cylinder (radius, length); sphere (radius,)
    line: int | None
    filename: str | None = None
    scale: Vec3 = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class Shape:
    """A <visual> or <collision> element."""

    origin: Pose
    geometry: Geometry | None
    line: int | None
    material: str | None = None


@dataclass(frozen=True)
class Inertial:
    """An <inertial>: mass [kg] and inertia [kg·m²], None where missing or unparsed."""

    origin: Pose
    mass: float | None
    inertia: tuple[float, float, float, float, float, float] | None  # ixx ixy ixz iyy iyz izz
    line: int | None
    mass_line: int | None
    inertia_line: int | None


@dataclass(frozen=True)
class Link:
    """A <link>: its inertial and its visual and collision shapes."""

    name: str
    line: int | None
    inertial: Inertial | None
    visuals: tuple[Shape, ...]
    collisions: tuple[Shape, ...]


@dataclass(frozen=True)
class Limit:
    """A <limit>: lower/upper [rad or m], effort [N·m or N], velocity, acceleration [/s, /s²]."""

    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None
    line: int | None
    missing_bounds: tuple[str, ...] = ()  # "lower"/"upper" absent (URDF reads them as 0)
    acceleration: float | None = None  # [rad/s² or m/s²] URDF 1.2's optional attribute


@dataclass(frozen=True)
class Joint:
    """A <joint>: its links, origin, axis, limit, damping, friction and mimic, with lines."""

    name: str
    type: str
    line: int | None
    parent: str | None
    child: str | None
    origin: Pose
    axis: Vec3 | None
    axis_line: int | None
    limit: Limit | None
    damping: float
    friction: float
    mimic: str | None = None
    mimic_line: int | None = None
    mimic_multiplier: float = 1.0  # q = multiplier * q_mimic + offset
    mimic_offset: float = 0.0

    @property
    def movable(self) -> bool:
        """Whether the joint moves along one axis: any type but fixed, floating and planar."""
        return JOINT_DOF.get(self.type, 1) == 1  # an unknown type is reported elsewhere


@dataclass(frozen=True)
class Material:
    """A <material>: name, rgba colour, and whether it is declared at the robot's top level."""

    name: str
    rgba: tuple[float, ...] | None
    line: int | None
    top_level: bool
    texture: str | None = None  # <texture filename=...>


@dataclass(frozen=True)
class Plugin:
    """A <plugin> anywhere in the document: a Gazebo system's, or ros2_control hardware's."""

    filename: str | None
    name: str | None
    params: Mapping[str, str]  # child tag -> its stripped text, the first of each tag
    line: int | None


@dataclass(frozen=True)
class Gazebo:
    """A top-level <gazebo>: the link or joint it is about (None: the robot) and its values.

    `values` maps each child tag (`mu1`, `mu2`, `material`, ...) to its `value` attribute,
    else its stripped text, the first of each tag.
    """

    reference: str | None
    values: Mapping[str, str]
    line: int | None


@dataclass(frozen=True)
class GazeboSensor:
    """A <sensor> in a top-level <gazebo> (classic or Harmonic), its numbers as written.

    A number that is missing or not a number is None; `rays` and `vertical` are a scan's
    (samples, min angle, max angle), `range` a lidar's (min, max) and `clip` a camera's
    (near, far) [m]; `pose` is the sensor's in its link (x y z roll pitch yaw).
    """

    name: str
    type: str  # Gazebo's: ray, gpu_ray, lidar, gpu_lidar, camera, depth, depth_camera, imu, ...
    link: str | None  # the <gazebo reference>
    line: int | None
    pose: tuple[float, ...] | None = None
    update_rate: float | None = None
    frame: str | None = None  # the plugin's frame_name, or Harmonic's gz_frame_id
    rays: tuple[float | None, float | None, float | None] | None = None
    vertical: tuple[float | None, float | None, float | None] | None = None
    range: tuple[float | None, float | None] | None = None
    horizontal_fov: float | None = None
    clip: tuple[float | None, float | None] | None = None

    @property
    def is_lidar(self) -> bool:
        """Whether it casts rays (Gazebo's ray, gpu_ray, lidar, gpu_lidar)."""
        return self.type in ("ray", "gpu_ray", "lidar", "gpu_lidar")


@dataclass(frozen=True)
class Ros2Control:
    """A top-level <ros2_control>: its hardware plugin and the joints' command interfaces."""

    name: str
    hardware: str  # <hardware><plugin> class, stripped ("" when there is none)
    commands: Mapping[str, tuple[str, ...]]  # joint -> command interface names
    line: int | None


@dataclass(frozen=True)
class Transmission:
    """A top-level <transmission>: the joints it drives."""

    name: str
    joints: tuple[str, ...]
    line: int | None


@dataclass(frozen=True)
class Urdf:
    """One URDF document: links, joints, materials, and the Gazebo/ros2_control extensions."""

    name: str
    source: str
    text: bytes
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    materials: tuple[Material, ...]
    problems: tuple[NumberProblem, ...] = field(default=())
    line: int | None = None  # the <robot> element's
    notes: tuple[str, ...] = ()  # `note: ...`/`warning: ...` lines: xacro arguments used, ...
    # a xacro expansion's element lines -> where they were written (xacro.lines); empty else
    origins: Mapping[int, Origin] = field(default_factory=dict)
    # the simulator extensions, read once by urdf/extensions.py
    gazebo: tuple[Gazebo, ...] = ()
    ros2_control: tuple[Ros2Control, ...] = ()
    transmissions: tuple[Transmission, ...] = ()
    plugins: tuple[Plugin, ...] = ()  # every <plugin>, in document order
    sensors: tuple[GazeboSensor, ...] = ()  # every <gazebo><sensor>, in document order

    def link(self, name: str) -> Link | None:
        """The link called `name`, or None."""
        return next((lk for lk in self.links if lk.name == name), None)
