"""What a simulate run is told besides its robot file: built once (by the CLI or a caller).

The robot (a spec's standalone arm or a URDF file, read once) is the `RobotFile` handed
beside these options; they hold no file path to read it again.

A frozen dataclass with `Literal` choices, so a typo in an integrator name is a type error
for library callers and a listed choice in `armcli simulate --help`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Literal, get_args

from armcli.errors import InputError

if TYPE_CHECKING:
    from armcli.trajectory.message import Trajectory

Integrator = Literal["euler", "rk4"]
"""euler: semi-implicit Euler, Kd and damping implicit (first order; symplectic only for a
constant mass matrix, see sim/simulate.py); rk4: classic Runge-Kutta, split at knots."""

INTEGRATORS: tuple[str, ...] = get_args(Integrator)


@dataclass(frozen=True)
class SimOptions:
    """Options of one simulate run; None means "take it from the spec" (or the default).

    Attributes:
        trajectory: JointTrajectory YAML file, or a `Trajectory` a library call built
            (exactly one of trajectory / message).
        message: JointTrajectory as YAML text.
        joints: joints to move; the others are locked at their start value.
        kp: P gain(s) [N·m/rad or N/m]: one value for all joints or one per joint.
        kd: D gain(s) [N·m·s/rad or N·s/m], same shape rule as kp.
        gravity_comp: add g(q) to the PD torque.
        dt: time step [s].
        integrator: see `Integrator`.
        duration: simulated time [s] (default: last point + settle time).
        clamp: clamp trajectory positions outside the limits instead of refusing.
        rate: joint-state output rate [Hz].
    """

    trajectory: Path | Trajectory | None = None
    message: str | None = None
    joints: tuple[str, ...] | None = None
    kp: tuple[float, ...] | None = None
    kd: tuple[float, ...] | None = None
    gravity_comp: bool | None = None
    dt: float | None = None
    integrator: Integrator = "euler"
    duration: float | None = None
    clamp: bool = False
    rate: float | None = None

    def __post_init__(self) -> None:
        if self.integrator not in INTEGRATORS:
            raise InputError(
                f"unknown value {self.integrator!r}; valid: {', '.join(INTEGRATORS)}",
                field="SimOptions.integrator",
            )
