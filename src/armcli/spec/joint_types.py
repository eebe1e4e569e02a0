"""The one joint-type table: every URDF joint type, the freedoms it adds, which need limits.

Plain Python (no pydantic), in the lowest layer that names joint types, so the spec
models, the URDF reader and the checks all import it and no module lists types itself.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Literal, Protocol

JointType = Literal["revolute", "continuous", "prismatic", "fixed", "floating", "planar"]

# Every URDF joint type and the degrees of freedom it adds.
JOINT_DOF: dict[str, int] = {
    "fixed": 0,
    "revolute": 1,
    "continuous": 1,
    "prismatic": 1,
    "floating": 6,
    "planar": 3,
}
JOINT_TYPES: tuple[str, ...] = tuple(JOINT_DOF)
MOVABLE_TYPES: tuple[str, ...] = tuple(k for k, n in JOINT_DOF.items() if n > 0)
ONE_DOF_TYPES: tuple[str, ...] = tuple(k for k, n in JOINT_DOF.items() if n == 1)
# The types URDF requires position limits of (a continuous joint's are ignored).
LIMITED_TYPES: tuple[str, ...] = ("revolute", "prismatic")
ROTARY_TYPES: tuple[str, ...] = ("revolute", "continuous")  # the rest of one DoF slides
AXIS_TYPES: tuple[str, ...] = (*ONE_DOF_TYPES, "planar")  # types whose <axis> URDF reads


def total_dof(joint_types: Iterable[str]) -> int:
    """Degrees of freedom of joints of these types (a floating joint adds 6; unknown types 0)."""
    return sum(JOINT_DOF.get(t, 0) for t in joint_types)


class _Bounds(Protocol):
    @property
    def lower(self) -> float | None: ...
    @property
    def upper(self) -> float | None: ...


def position_bounds(joint_type: str, limit: _Bounds | None) -> tuple[float, float] | None:
    """(lower, upper) [rad or m] of a bounded joint; None when it has no position limits.

    A continuous joint is unbounded even if its <limit> carries lower/upper (URDF ignores
    them), so every user (spec or URDF) asks here rather than testing the type itself.
    """
    if joint_type == "continuous" or limit is None:
        return None
    if limit.lower is None or limit.upper is None:
        return None
    return (float(limit.lower), float(limit.upper))
