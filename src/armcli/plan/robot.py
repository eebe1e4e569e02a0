"""What a plan adds to the robot it moves: the planned joints, their limits, named poses.

`load_plan_robot` loads the robot once (`Robot.load`, the strict loader) with a fixed root,
so the arm is checked against its own mobile base, and its collision geometry. `PlanRobot`
keeps only what is plan's over that `Robot`: which joints are planned (the free 1-DoF
joints a plan moves; mimic followers follow their leaders), their accelerations, the named
poses and whether the robot stands on the ground. Its limit arrays are views of the
robot's, per planned joint; every other 1-DoF joint stays where the robot says an unset
joint rests (`Robot.rest`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.defaults import DEFAULT_JOINT_ACCELERATION
from armcli.errors import InputError
from armcli.robot.joints import JointMap, span
from armcli.robot.mimic import Mimic, mimics
from armcli.robot.model import Robot
from armcli.urdf.doc import Urdf
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

MOVABLE = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class PlanRobot:
    """A robot and the joints a plan moves; the arrays are per planned joint, in `joints` order.

    `q(x)` maps planned joint values [rad or m] to Pinocchio's configuration vector.
    """

    robot: Robot  # the whole robot, fixed root: q, limits, mimic couplings, tool, kinematics
    geometry: Any  # pinocchio.GeometryModel of the robot's collision shapes
    joints: tuple[str, ...]
    acceleration: np.ndarray  # [rad/s² or m/s²]: the spec's, the URDF's or the default
    poses: Mapping[str, Mapping[str, float]]  # named poses: spec poses or SRDF group states
    mobile: bool = False  # stands on the ground: the ground plane is an obstacle
    spec: RobotSpec | None = None
    acceleration_defaulted: tuple[str, ...] = ()  # joints given DEFAULT_JOINT_ACCELERATION
    held: Mapping[str, float] = field(default_factory=dict)  # unplanned joints not at rest

    @property
    def model(self) -> Any:
        """The robot's pinocchio.Model (fixed root)."""
        return self.robot.model

    @property
    def urdf(self) -> Urdf:
        """The document the robot was loaded from."""
        assert self.robot.urdf is not None  # load_plan_robot loads from one
        return self.robot.urdf

    @property
    def mimic(self) -> tuple[Mimic, ...]:
        """The robot's mimic couplings, leaders first."""
        return self.robot.mimics

    @cached_property
    def _index(self) -> list[int]:
        """Each planned joint's position in `robot.joints`."""
        return [self.robot.names.index(j) for j in self.joints]

    @cached_property
    def lower(self) -> np.ndarray:
        """[rad or m] each planned joint's lower limit; -pi for a continuous joint."""
        return np.array([span(*self._range(k))[0] for k in self._index])

    @cached_property
    def upper(self) -> np.ndarray:
        """[rad or m] each planned joint's upper limit; pi for a continuous joint."""
        return np.array([span(*self._range(k))[1] for k in self._index])

    def _range(self, k: int) -> tuple[float, float]:
        return float(self.robot.lower[k]), float(self.robot.upper[k])

    @cached_property
    def velocity(self) -> np.ndarray:
        """[rad/s or m/s] each planned joint's velocity limit; inf when the URDF gives none."""
        v = self.robot.velocity[self._index]
        return np.where((v > 0) & np.isfinite(v), v, math.inf)

    @cached_property
    def effort(self) -> np.ndarray:
        """[N·m or N] each planned joint's effort limit; inf when the URDF gives none."""
        return np.array(self.robot.effort[self._index])

    @property
    def tool_frame(self) -> int:
        """The frame id of the tool point's link."""
        return self.robot.tool_frame

    @property
    def tool_offset(self) -> np.ndarray:
        """[m] the tool point in its link's frame."""
        assert self.robot.tool is not None  # load_plan_robot refuses a robot without one
        return np.array(self.robot.tool.xyz, dtype=float)

    @property
    def tool_label(self) -> str:
        """How reports name the tool point."""
        assert self.robot.tool is not None
        return self.robot.tool.label

    @cached_property
    def rest(self) -> dict[str, float]:
        """Every 1-DoF joint not planned: at its `held` value, else its rest (`Robot.rest`)."""
        return {
            j.name: float(self.held.get(j.name, j.rest))
            for j in self.robot.joints
            if j.name not in self.joints
        }

    @cached_property
    def _map(self) -> JointMap:
        return self.robot.joint_map(self.joints, self.rest)

    def q(self, x: Sequence[float] | np.ndarray) -> np.ndarray:
        """Pinocchio configuration with the planned joints at `x` and followers following.

        Every other 1-DoF joint at its `rest` value; multi-DoF joints stay neutral. Vectorised
        (`Robot.joint_map`, tested against `q_slow`): the planner calls it per state.
        """
        return self._map.q(np.asarray(x, dtype=float))

    def q_slow(self, x: Sequence[float] | np.ndarray) -> np.ndarray:
        """`q` joint by joint through `Robot.q`."""
        values = dict(self.rest)
        values.update(zip(self.joints, (float(v) for v in x), strict=True))
        return self.robot.q(self.robot.follow(values))

    def v_indices(self) -> list[int]:
        """Velocity indices of the planned joints in the model (for Jacobians and torques)."""
        return [self.robot.joint(j).idx_v for j in self.joints]

    def pose(self, name: str) -> np.ndarray:
        """Planned joint values of a named pose; joints it leaves out stay at rest."""
        if name not in self.poses:
            valid = ", ".join(sorted(self.poses)) or "none"
            raise InputError(f"unknown pose {name!r}; valid: {valid}", field="pose")
        given = self.poses[name]
        return np.array([given.get(j, self.robot.rest(j)) for j in self.joints], dtype=float)


def default_joints(urdf: Urdf, spec: RobotSpec | None) -> tuple[str, ...]:
    """The arm's movable joints (the spec's arm; every joint of a URDF), without followers."""
    followers = {m.follower for m in mimics(urdf.joints)}
    movable = [j.name for j in urdf.joints if j.type in MOVABLE and j.name not in followers]
    if spec is not None:
        arm = set(spec.arm.joints)
        movable = [j for j in movable if j in arm]
    return tuple(movable)


def load_plan_robot(
    robot: RobotFile,
    *,
    joints: Sequence[str] | None = None,
    search: MeshSearch | None = None,
    group_states: Mapping[str, Mapping[str, float]] | None = None,
) -> PlanRobot:
    """A robot file (spec or URDF) -> PlanRobot; the one model loader of `plan`.

    `joints`: the planned joints (default: `default_joints`); `group_states`: named poses
    from an SRDF, beside the spec's poses.
    """
    urdf, spec = robot.robot, robot.spec
    loaded = Robot.load(urdf, spec=spec)
    geometry = loaded.collision_model(search or MeshSearch())
    followers = {m.follower for m in loaded.mimics}
    chosen = tuple(joints) if joints else default_joints(urdf, spec)
    valid = [j.name for j in urdf.joints if j.type in MOVABLE and j.name not in followers]
    for name in chosen:
        if name not in valid:
            raise InputError(f"unknown joint {name!r}; valid: {', '.join(valid)}", field="joints")
    if len(set(chosen)) != len(chosen):
        raise InputError("a joint is listed twice", field="joints")
    if not chosen:
        raise InputError("this robot has no movable joint to plan for", file=urdf.source)
    acc, defaulted = _accelerations(urdf, spec, chosen)
    _ = loaded.tool_frame  # a link, not a joint of the same name (ANYmal C); else InputError
    poses: dict[str, Mapping[str, float]] = dict(group_states or {})
    if spec is not None:
        poses.update({name: spec.pose(name) for name in spec.poses})
    return PlanRobot(
        loaded,
        geometry,
        chosen,
        acc,
        poses,
        mobile=spec is not None and spec.mobile_base is not None,
        spec=spec,
        acceleration_defaulted=defaulted,
    )


def _accelerations(
    urdf: Urdf, spec: RobotSpec | None, joints: Sequence[str]
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Each joint's acceleration limit [rad/s² or m/s²], and the joints given the default.

    The spec's limit, else the URDF's, else DEFAULT_JOINT_ACCELERATION.
    """
    by_name = {j.name: j for j in urdf.joints}
    spec_acc = _spec_accelerations(spec)
    out, defaulted = [], []
    for name in joints:
        lim = by_name[name].limit
        a = spec_acc.get(name) or (lim.acceleration if lim is not None else None)
        if not a:
            a = DEFAULT_JOINT_ACCELERATION
            defaulted.append(name)
        out.append(float(a))
    return np.array(out), tuple(defaulted)


def _spec_accelerations(spec: RobotSpec | None) -> dict[str, float]:
    """The spec's `limit.acceleration` per joint, where given."""
    if spec is None:
        return {}
    out = {}
    for name, joint in spec.all_joints().items():
        lim = getattr(joint, "limit", None)
        a = getattr(lim, "acceleration", None) if lim is not None else None
        if a:
            out[name] = float(a)
    return out


def robot_path(robot: RobotFile) -> Path:
    """The file the robot came from (errors name it)."""
    return robot.path
