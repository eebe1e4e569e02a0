"""The robot a plan moves: Pinocchio model, planned joints and their limits, collision geometry.

`load_plan_robot` is the one place this package loads a model (robot.load's checked
loader; `PlanRobot.q_slow` is `robot.model.Robot.q`). The whole robot is loaded with
a fixed root, so the arm is checked against its own mobile base. Planned joints are the
free 1-DoF joints a plan moves; mimic followers follow their leaders; every other joint
stays at its rest value (0, or the middle of its range when 0 is outside it).
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
from armcli.robot.frames import link_frame
from armcli.robot.load import checked_model
from armcli.robot.mimic import Mimic, follow, mimics
from armcli.robot.model import JointMap, Robot
from armcli.robot.tool import tool_point
from armcli.urdf.doc import Urdf
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile, urdf_text

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

MOVABLE = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class PlanRobot:
    """One loaded robot for planning; arrays are per planned joint, in `joints` order.

    `q(x)` maps planned joint values [rad or m] to Pinocchio's configuration vector.
    """

    model: Any  # pinocchio.Model, fixed root
    geometry: Any  # pinocchio.GeometryModel of the robot's collision shapes
    urdf: Urdf
    joints: tuple[str, ...]
    lower: np.ndarray  # [rad or m]
    upper: np.ndarray
    velocity: np.ndarray  # [rad/s or m/s]
    acceleration: np.ndarray  # [rad/s² or m/s²]
    effort: np.ndarray  # [N·m or N]; inf when none
    tool_frame: int
    tool_offset: np.ndarray  # [m] in the tool link's frame
    tool_label: str
    poses: Mapping[str, Mapping[str, float]]  # named poses: spec poses or SRDF group states
    mimic: tuple[Mimic, ...] = ()
    rest: Mapping[str, float] = field(default_factory=dict)  # every other 1-DoF joint
    mobile: bool = False  # stands on the ground: the ground plane is an obstacle
    spec: RobotSpec | None = None
    acceleration_defaulted: tuple[str, ...] = ()  # joints given DEFAULT_JOINT_ACCELERATION

    @cached_property
    def robot(self) -> Robot:
        """The model's robot handle (`Robot.q` builds the configuration)."""
        return Robot(self.model, mimics=self.mimic)

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
        return self.robot.q(follow(self.mimic, values))

    def v_indices(self) -> list[int]:
        """Velocity indices of the planned joints in the model (for Jacobians and torques)."""
        return [int(self.model.joints[self.model.getJointId(j)].idx_v) for j in self.joints]

    def pose(self, name: str) -> np.ndarray:
        """Planned joint values of a named pose; joints it leaves out stay at rest."""
        if name not in self.poses:
            valid = ", ".join(sorted(self.poses)) or "none"
            raise InputError(f"unknown pose {name!r}; valid: {valid}", field="pose")
        given = self.poses[name]
        return np.array([given.get(j, self.rest_of(j)) for j in self.joints], dtype=float)

    def rest_of(self, joint: str) -> float:
        """A planned joint's default value: 0 clipped into its range."""
        i = self.joints.index(joint)
        return float(np.clip(0.0, self.lower[i], self.upper[i]))


def _rest(lo: float, hi: float) -> float:
    return 0.0 if lo <= 0.0 <= hi else 0.5 * (lo + hi)


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
    model = checked_model(urdf).model
    urdf_text(urdf)  # refuses a non-UTF-8 document before Pinocchio sees it
    geometry = Robot(model, source=urdf.source, urdf=urdf).collision_model(search or MeshSearch())
    followers = {m.follower for m in mimics(urdf.joints)}
    chosen = tuple(joints) if joints else default_joints(urdf, spec)
    by_name = {j.name: j for j in urdf.joints}
    valid = [j.name for j in urdf.joints if j.type in MOVABLE and j.name not in followers]
    for name in chosen:
        if name not in valid:
            raise InputError(f"unknown joint {name!r}; valid: {', '.join(valid)}", field="joints")
    if len(set(chosen)) != len(chosen):
        raise InputError("a joint is listed twice", field="joints")
    if not chosen:
        raise InputError("this robot has no movable joint to plan for", file=urdf.source)
    lower, upper, vel, acc, eff, defaulted = [], [], [], [], [], []
    spec_acc = _spec_accelerations(spec)
    for name in chosen:
        j = by_name[name]
        lim = j.limit
        if j.type == "continuous" or lim is None:
            lo, hi = -math.pi, math.pi
        else:
            lo, hi = float(lim.lower or 0.0), float(lim.upper or 0.0)
        lower.append(lo)
        upper.append(hi)
        v = lim.velocity if lim is not None and lim.velocity else math.inf
        vel.append(float(v))
        e = lim.effort if lim is not None and lim.effort else math.inf
        eff.append(float(e))
        a = spec_acc.get(name) or (lim.acceleration if lim is not None else None)
        if not a:
            a = DEFAULT_JOINT_ACCELERATION
            defaulted.append(name)
        acc.append(float(a))
    rest = {
        j.name: _rest(float(j.limit.lower or 0.0), float(j.limit.upper or 0.0))
        if j.limit is not None and j.type != "continuous"
        else 0.0
        for j in urdf.joints
        if j.type in MOVABLE and j.name not in chosen
    }
    tool = tool_point(urdf, spec)
    tool_frame = link_frame(model, tool.link) if tool is not None else None
    if tool is None or tool_frame is None:  # a link, not a joint of the same name (ANYmal C)
        raise InputError("this URDF has no link to use as the tool point", file=urdf.source)
    poses: dict[str, Mapping[str, float]] = dict(group_states or {})
    if spec is not None:
        poses.update({name: spec.pose(name) for name in spec.poses})
    return PlanRobot(
        model=model,
        geometry=geometry,
        urdf=urdf,
        joints=chosen,
        lower=np.array(lower),
        upper=np.array(upper),
        velocity=np.array(vel),
        acceleration=np.array(acc),
        effort=np.array(eff),
        tool_frame=tool_frame,
        tool_offset=np.array(tool.xyz, dtype=float),
        tool_label=tool.label,
        poses=poses,
        mimic=tuple(mimics(urdf.joints)),
        rest=rest,
        mobile=spec is not None and spec.mobile_base is not None,
        spec=spec,
        acceleration_defaulted=tuple(defaulted),
    )


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
