"""Joints: type, frames, axis, limits, dynamics, and URDF's mimic, safety and calibration tags."""

from __future__ import annotations

import math

from pydantic import Field, model_validator

from armcli.spec.joint_types import LIMITED_TYPES, ONE_DOF_TYPES, JointType, position_bounds
from armcli.spec.passthrough import PassthroughElement
from armcli.spec.shapes import Origin
from armcli.spec.types import NonNeg, Real, UrdfName, Vec3, _Model


class Limit(_Model):
    """Joint limits: `lower`/`upper`, `effort`, `velocity` and an optional `acceleration`.

    Units: [rad or m], [N·m or N], [rad/s or m/s], [rad/s² or m/s²].

    Revolute and prismatic joints need `lower` and `upper`; a continuous joint has none
    (a URDF may still write them, and they are kept). An effort or velocity of 0 is what
    some URDFs write for "not given".
    """

    lower: Real | None = Field(None, description="lower position limit [rad or m]")
    upper: Real | None = Field(None, description="upper position limit [rad or m], >= lower")
    effort: NonNeg = Field(description="largest motor torque or force [N·m or N]")
    velocity: NonNeg = Field(description="largest speed [rad/s or m/s]")
    acceleration: NonNeg | None = Field(
        None,
        description="largest acceleration [rad/s² or m/s²] (URDF 1.2's `<limit acceleration>`); "
        "`plan` and the MoveIt joint_limits.yaml use 1.0 when absent (MoveIt's default)",
    )


class Dynamics(_Model):
    """Joint `friction` [N·m or N] and viscous `damping` [N·m·s/rad or N·s/m]."""

    friction: NonNeg = Field(
        0.0, description="Coulomb (static) friction torque or force [N·m or N]"
    )
    damping: NonNeg = Field(0.0, description="viscous damping [N·m·s/rad or N·s/m]")


class Mimic(_Model):
    """This joint follows another: q = multiplier * q_joint + offset (grippers, linkages)."""

    joint: UrdfName = Field(description="the joint followed (the lead)")
    multiplier: Real = Field(1.0, description="gear ratio to the lead joint [-]")
    offset: Real = Field(0.0, description="position at lead position 0 [rad or m]")


class SafetyController(_Model):
    """URDF's <safety_controller>: soft limits and the gains that enforce them."""

    soft_lower_limit: Real = Field(0.0, description="soft lower position limit [rad or m]")
    soft_upper_limit: Real = Field(0.0, description="soft upper position limit [rad or m]")
    k_position: Real = Field(0.0, description="position gain of the soft limits [1/s]")
    k_velocity: Real = Field(description="velocity gain: effort limit per speed [N·m·s/rad]")


class Calibration(_Model):
    """URDF's <calibration>: positions of the reference switch edges."""

    rising: Real | None = Field(None, description="rising edge position [rad or m]")
    falling: Real | None = Field(None, description="falling edge position [rad or m]")


class Joint(_Model):
    """A URDF joint from `parent` to `child`; revolute and prismatic joints need a `limit`.

    `origin` places the joint frame in the parent link's frame; `axis` is a non-zero vector
    in the joint frame.
    """

    type: JointType = Field(
        description="revolute, continuous, prismatic, fixed, floating or planar"
    )
    parent: UrdfName = Field(description="parent link name")
    child: UrdfName = Field(description="child link name")
    origin: Origin = Field(Origin(), description="pose of the joint frame in the parent link frame")
    axis: Vec3 = Field(
        (0.0, 0.0, 1.0),
        description="rotation or translation axis in the joint frame (non-zero) [-]",
    )
    limit: Limit | None = Field(
        None, description="limits; required for revolute and prismatic joints"
    )
    dynamics: Dynamics | None = Field(None, description="friction and damping")
    mimic: Mimic | None = Field(None, description="follow another joint (e.g. a gripper finger)")
    safety_controller: SafetyController | None = Field(None, description="soft limits")
    calibration: Calibration | None = Field(None, description="reference switch positions")
    passthrough: list[PassthroughElement] = Field(
        [], description="elements inside <joint> kept verbatim (non-URDF extensions)"
    )

    @model_validator(mode="after")
    def _limits(self) -> Joint:
        if self.type in LIMITED_TYPES:
            if self.limit is None:
                raise ValueError(f"a {self.type} joint needs a limit")
            if self.limit.lower is None or self.limit.upper is None:
                raise ValueError(f"a {self.type} joint's limit needs lower and upper")
        if self.type != "fixed" and math.fsum(a * a for a in self.axis) < 1e-12:
            raise ValueError("axis must be non-zero")
        if self.mimic is not None and self.type not in ONE_DOF_TYPES:
            raise ValueError(f"a {self.type} joint cannot mimic another")
        return self

    @property
    def bounds(self) -> tuple[float, float] | None:
        """(lower, upper) [rad or m] of a bounded joint, else None (continuous: always None)."""
        return position_bounds(self.type, self.limit)
