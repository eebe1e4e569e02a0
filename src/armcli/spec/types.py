"""The field types every spec model shares: finite numbers (or pi expressions) and names.

One definition of a number, a positive number, a name, so that a mass, a limit and
a sensor rate are validated the same way everywhere in the spec.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field

from armcli.defaults import MAX_DT
from armcli.errors import InputError
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


def time_step_problem(dt: float) -> str | None:
    """Why `dt` [s] is no usable time step (the one rule: finite, in (0, MAX_DT]), or None."""
    if math.isfinite(dt) and 0.0 < dt <= MAX_DT:
        return None
    return f"must be finite and in (0, {MAX_DT:g}] s, got {dt:g}"


def time_step(dt: float, field: str) -> float:
    """`dt` [s] when it is a usable time step; else InputError naming `field`, the user's.

    `control.dt` (the spec), `SimOptions.dt` (simulate's and drive's `--dt`), `SimConfig.dt`
    (every rollout: simulate, tune, plan) all pass through this rule.
    """
    problem = time_step_problem(float(dt))
    if problem is not None:
        raise InputError(problem, field=field)
    return float(dt)


def _time_step(v: float) -> float:
    problem = time_step_problem(v)
    if problem is not None:
        raise ValueError(problem)
    return v


Real = Annotated[float, BeforeValidator(_number), AfterValidator(_finite)]
TimeStep = Annotated[float, BeforeValidator(_number), AfterValidator(_time_step)]  # [s]
Positive = Annotated[Real, Field(gt=0)]
NonNeg = Annotated[Real, Field(ge=0)]
Unit = Annotated[Real, Field(ge=0, le=1)]
Vec3 = tuple[Real, Real, Real]
# Names that also become xacro properties, file names and ROS names.
Name = Annotated[str, Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]*$", max_length=64)]
# A robot name: also file names (`NAME.urdf`) and, where ROS allows it, the package prefix.
RobotName = Annotated[str, Field(pattern=r"^[A-Za-z0-9_][A-Za-z0-9_-]*$", max_length=64)]
# Link and joint names as URDFs write them (`joint_0.0`, `LFoot/FSR/Heel_sensor`): no
# spaces, quotes or `$`, which xacro would read as an expression.
UrdfName = Annotated[str, Field(pattern=r"^[A-Za-z0-9_][A-Za-z0-9_./-]*$", max_length=128)]
# Free text that ends up in XML attributes or text (URIs, plugin names, topics).
Text = Annotated[str, Field(min_length=1, max_length=1024, pattern=r"^[^\x00-\x1f]*$")]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
