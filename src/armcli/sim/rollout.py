"""The simulator's rollout: PD motor, implicit damping, friction and joint stops.

One step (semi-implicit Euler, the default) at state (q, v) and reference (q_ref, v_ref):

1. motor torque tau = Kp (q_ref - q) + Kd (v_ref - v) [+ g(q)], saturated at the effort limit;
2. velocity-proportional torques (Kd of unsaturated joints, viscous damping D) are implicit:
   (M + dt B)(v* - v)/dt = tau_explicit - B v - nle, with B = diag(Kd + D). ABA adds
   `model.armature` to the diagonal of M, so armature = dt B gives exactly this, and the
   step is stable for any non-negative Kd and D;
3. Coulomb friction and joint stops are solved at velocity level, like MuJoCo's
   frictionloss and limit constraints: v' = argmin ½|v - v*|²_(M+dtB) + dt Σ F_i |v_i|
   subject to the stop bounds, by projected Gauss-Seidel. A joint at rest with a small
   torque stays exactly at rest (no chatter), and since v = 0 is feasible the projection
   never adds kinetic energy;
4. the motor torque over the whole step, tau - Kd (v' - v), must respect the effort limit
   too: a joint whose implicit Kd would push it past the limit is saturated and the step
   solved again, so the reported torque is the applied torque and never exceeds the limit;
5. q' = q + dt v', clamped to the limits against round-off.

RK4 integrates the smooth part (PD, gravity, damping) with the classic four stages, all
explicit, on reference samples from one polynomial piece per step (so a knot between
steps does not cost the method its order), then applies the same projection.

`stepper.py` holds the step in plain Python floats (the reference and the fallback);
`_native/rollout.cpp` runs the identical algorithm compiled (`native.py`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.sim.fastloop import euler_loop, rk4_loop
from armcli.sim.stepper import DAMPING as DAMPING
from armcli.sim.stepper import EFFORT as EFFORT
from armcli.sim.stepper import ENERGY_EVERY as ENERGY_EVERY
from armcli.sim.stepper import FAIL_ENERGY as FAIL_ENERGY
from armcli.sim.stepper import FAIL_NONE as FAIL_NONE
from armcli.sim.stepper import FAIL_NONFINITE as FAIL_NONFINITE
from armcli.sim.stepper import FAIL_VELOCITY as FAIL_VELOCITY
from armcli.sim.stepper import FLAG_SATURATED as FLAG_SATURATED
from armcli.sim.stepper import FLAG_STOP as FLAG_STOP
from armcli.sim.stepper import FRICTION as FRICTION
from armcli.sim.stepper import KD as KD
from armcli.sim.stepper import KP as KP
from armcli.sim.stepper import LOWER as LOWER
from armcli.sim.stepper import PARAM_FIELDS as PARAM_FIELDS
from armcli.sim.stepper import UPPER as UPPER
from armcli.sim.stepper import VABORT as VABORT
from armcli.sim.stepper import Stepper

# Pinocchio joint model -> the joint code both engines use (revolute 0-3, prismatic 4-7,
# continuous 8-11: a revolute joint without limits, configuration (cos, sin) in Pinocchio).
JOINT_TYPES = {
    "JointModelRX": 0,
    "JointModelRY": 1,
    "JointModelRZ": 2,
    "JointModelRevoluteUnaligned": 3,
    "JointModelPX": 4,
    "JointModelPY": 5,
    "JointModelPZ": 6,
    "JointModelPrismaticUnaligned": 7,
    "JointModelRUBX": 8,
    "JointModelRUBY": 9,
    "JointModelRUBZ": 10,
    "JointModelRevoluteUnboundedUnaligned": 11,
}
RK4_ROWS = 3  # reference rows per RK4 step: t, t + dt/2, t + dt (one polynomial piece)


@dataclass(frozen=True)
class Plant:
    """Everything a rollout needs besides the initial state and the reference."""

    model: Any  # pinocchio.Model of one-dof joints (a continuous joint: nq 2, nv 1)
    params: np.ndarray  # (n, len(PARAM_FIELDS))
    gravity_comp: bool
    dt: float  # [s]
    integrator: str  # "euler" | "rk4"
    energy_max: float  # [J] kinetic energy treated as a blow-up


@dataclass(frozen=True)
class Rollout:
    """States at every step; a failed run stops at `fail_step` (rows after it are unset)."""

    q: np.ndarray  # (steps + 1, n) [rad or m]
    v: np.ndarray  # (steps + 1, n)
    tau: np.ndarray  # (steps, n) motor torque applied during each step [N·m or N]
    flags: np.ndarray  # (steps, n) uint8: FLAG_SATURATED | FLAG_STOP
    fail_step: int  # -1 when the run completed
    fail_joint: int  # index, -1 when not joint-specific
    fail_code: int


def rows_per_step(integrator: str) -> int:
    """Reference rows one step consumes.

    [q_ref, v_ref] at t (Euler) or at t, t + dt/2, t + dt (RK4). A reference for N steps
    has N * rows + 1 rows (the last: t = N dt).
    """
    return RK4_ROWS if integrator == "rk4" else 1


def steps_of(plant: Plant, ref: np.ndarray) -> int:
    """How many steps the reference table `ref` drives."""
    return int((ref.shape[0] - 1) // rows_per_step(plant.integrator))


def rollout_python(plant: Plant, q0: np.ndarray, v0: np.ndarray, ref: np.ndarray) -> Rollout:
    """Reference implementation and fallback of `native.rollout` (same contract)."""
    s = Stepper(plant.model, plant.params, plant.gravity_comp, plant.dt)
    n = s.n
    steps = steps_of(plant, ref)
    table = np.asarray(ref, dtype=float)
    q, v = [float(x) for x in q0], [float(x) for x in v0]
    if plant.integrator == "rk4":  # the reference, sampled once, as Python floats
        rec = rk4_loop(s, q, v, table[: RK4_ROWS * steps].tolist(), plant.energy_max)
    else:
        Rq, Rv = table[:steps, :n].tolist(), table[:steps, n:].tolist()
        rec = euler_loop(s, q, v, Rq, Rv, plant.energy_max)
    F = np.zeros((steps, n), dtype=np.uint8)
    for k, row in rec.flagged:
        F[k] = row
    Q = np.full((steps + 1) * n, np.nan)
    V = np.full((steps + 1) * n, np.nan)
    T = np.full(steps * n, np.nan)
    Q[: len(rec.q)], V[: len(rec.v)], T[: len(rec.tau)] = rec.q, rec.v, rec.tau
    return Rollout(
        Q.reshape(-1, n),
        V.reshape(-1, n),
        T.reshape(-1, n),
        F,
        rec.fail_step,
        rec.fail_joint,
        rec.fail_code,
    )
