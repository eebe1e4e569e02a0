"""One closed-loop run on the compiled step: plant, reference, the states asked for.

The physics (PD motor, implicit damping, friction, joint stops, Euler and RK4) is defined
once, in `_native/rollout.cpp`, whose header describes the step. Here: what a run is given
(the per-joint parameters, the reference as its polynomial pieces, which steps to keep)
and what it returns (those states and running statistics over every state), so a long
run's memory is that of the states kept, not of its steps.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from armcli.sim import native
from armcli.sim.options import Integrator
from armcli.trajectory.reference import Reference

Failure = Literal["", "nonfinite", "velocity", "energy"]  # why a run stopped early
CHUNK_STEPS = 10_000  # steps per call into the engine, between progress reports


@dataclass(frozen=True)
class Plant:
    """Everything a run needs besides the start state and the reference; arrays per joint."""

    model: Any  # pinocchio.Model of one-dof joints (a continuous joint: nq 2, nv 1)
    kp: np.ndarray  # [N·m/rad or N/m]
    kd: np.ndarray  # [N·m·s/rad or N·s/m]
    damping: np.ndarray  # viscous [N·m·s/rad or N·s/m]
    friction: np.ndarray  # Coulomb [N·m or N]
    lower: np.ndarray  # stops [rad or m]; ±inf: none
    upper: np.ndarray
    effort: np.ndarray  # saturation [N·m or N]; inf: none
    vabort: np.ndarray  # |v| treated as divergence [rad/s or m/s]
    gravity_comp: bool
    dt: float  # [s]
    integrator: Integrator
    energy_max: float  # [J] kinetic energy treated as a blow-up


@dataclass(frozen=True)
class Trace:
    """The states kept: row j is the state after `step[j]` steps."""

    step: np.ndarray  # (K,) int
    q: np.ndarray  # (K, n) [rad or m]
    v: np.ndarray  # (K, n)
    q_ref: np.ndarray  # (K, n) reference at the state's time
    v_ref: np.ndarray
    tau: np.ndarray  # (K, n) motor torque applied from this state on (last state: last step's)
    saturated: np.ndarray  # (K, n) bool: that torque is at the effort limit
    stop: np.ndarray  # (K, n) bool: a stop constraint acted in that step


@dataclass(frozen=True)
class Stats:
    """Running statistics over every state of the run, kept or not; per joint."""

    states: int  # states seen (steps + 1 for a complete run)
    sum_e2: np.ndarray  # Σ (q - q_ref)² [rad² or m²]
    max_e: np.ndarray  # max |q - q_ref|
    last_e: np.ndarray  # q - q_ref of the last state
    last_out: np.ndarray  # (int) step of the last state outside the settle band; -1: none
    saturated_steps: np.ndarray  # (int) steps with the motor torque at the effort limit
    stop_rises: np.ndarray  # (int) times a joint's stop constraint engaged


@dataclass(frozen=True)
class Rollout:
    """A run's outcome; a failed run stops at `fail_step` (`failure` names why)."""

    trace: Trace
    stats: Stats
    q: np.ndarray  # the last state reached
    v: np.ndarray
    fail_step: int  # -1 when the run completed
    fail_joint: int  # index, -1 when not joint-specific
    failure: Failure  # "": the run completed


def run(
    plant: Plant,
    reference: Reference,
    q0: np.ndarray,
    v0: np.ndarray,
    steps: int,
    *,
    record: np.ndarray | None = None,
    settle_tol: float = 0.0,
    compiled: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> Rollout:
    """Run `steps` steps from (q0, v0), keeping the states at the `record` steps.

    `record` is strictly increasing (default: every step). `compiled` is
    `native.compiled_model` of the plant's model, built here when None. The statistics
    count a state outside the settle band when |q - q_ref| > `settle_tol`. The engine
    releases the GIL: runs parallelise on threads.
    """
    mod = native.require()
    model = compiled if compiled is not None else native.compiled_model(mod, plant.model)
    keep = np.arange(steps + 1, dtype=np.int64) if record is None else record
    r = mod.rollout(
        _compiled_plant(mod, model, plant),
        _compiled_reference(mod, reference),
        _vector(q0),
        _vector(v0),
        steps,
        np.ascontiguousarray(keep, dtype=np.int64),
        settle_tol,
    )
    fail_step, fail_joint, code = -1, -1, mod.FAIL_NONE
    while r.step < steps and code == mod.FAIL_NONE:
        fail_step, fail_joint, code = r.advance(CHUNK_STEPS)
        if progress is not None:
            progress(r.step, steps)
    failures: dict[int, Failure] = {
        mod.FAIL_NONE: "",
        mod.FAIL_NONFINITE: "nonfinite",
        mod.FAIL_VELOCITY: "velocity",
        mod.FAIL_ENERGY: "energy",
    }
    failure = failures[code]
    recs, stats = r.records(), r.statistics()
    flags = {"saturated": recs.pop("saturated").astype(bool), "stop": recs.pop("stop").astype(bool)}
    fields = Stats.__dataclass_fields__
    return Rollout(
        Trace(**recs, **flags),
        Stats(**{k: v for k, v in stats.items() if k in fields}),
        r.q,
        r.v,
        int(fail_step),
        int(fail_joint),
        failure,
    )


def _vector(x: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=float)


def _compiled_plant(mod: Any, model: Any, p: Plant) -> Any:
    return mod.plant(
        model,
        kp=_vector(p.kp),
        kd=_vector(p.kd),
        damping=_vector(p.damping),
        friction=_vector(p.friction),
        lower=_vector(p.lower),
        upper=_vector(p.upper),
        effort=_vector(p.effort),
        vabort=_vector(p.vabort),
        gravity_comp=p.gravity_comp,
        dt=p.dt,
        integrator=p.integrator,
        energy_max=p.energy_max,
    )


def _compiled_reference(mod: Any, ref: Reference) -> Any:
    return mod.reference(_vector(ref.knots), _vector(ref.coeffs).reshape(-1), _vector(ref.final))
