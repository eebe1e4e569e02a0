"""Simulate an arm under PD control along a reference: setup, stability check, results.

The step itself (implicit damping, friction, joint stops; Euler and RK4) is the compiled
engine's (`_native/rollout.cpp`, run by `rollout.py`). Here: which joints move (others are
locked), the per-joint parameters from the URDF, refused at this boundary when they are
not numbers or out of order, the linear stability check that refuses gains the integrator
cannot handle, and turning a run into a `SimResult` or a `SimulationError` that says when,
where and why.

Integrators. `euler` is semi-implicit Euler with the D gain and damping implicit: first
order, stable for any Kd, D >= 0. It is symplectic only while the mass matrix is constant
(a single joint, parallel prismatic axes): there its energy error stays bounded. On a
multi-link arm the Coriolis and centrifugal forces are taken at the step's start and a
conservative swing's energy drifts: +5.6e-2 J/h for the seed arm hanging from 0.3 rad at
dt = 1 ms (+3.5e-2 J/h at 0.5 ms; tests/sim/test_integrators.py). `rk4` is classic RK4,
exact across trajectory knots (the step is split there) and error-controlled after
reference velocity jumps; it treats everything explicitly, so dt (Kd + D) λ_max(M⁻¹) must
stay below ~2.8.

Gains the integrator cannot handle at dt are refused before the run with `check`'s verdict
for the same loop (`analysis/stability.py`, `analysis/verdict.py`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from armcli.analysis import pdloop
from armcli.analysis import verdict as verdicts
from armcli.defaults import DEFAULT_DT
from armcli.errors import InputError, SimulationError
from armcli.robot.model import LIMITS, Robot
from armcli.sim import native
from armcli.sim import rollout as ro
from armcli.sim.options import INTEGRATORS, Integrator
from armcli.spec.types import time_step
from armcli.trajectory.reference import Reference

VEL_ABORT_FACTOR = 10.0  # divergence when |v| exceeds this times the URDF velocity limit
DEFAULT_VABORT = 1000.0  # [rad/s or m/s] when the URDF gives no velocity limit
SETTLE_TOL = 0.01  # [rad or m] |q - q_ref| band for "settled"
MAX_STEPS = 2_000_000  # the longest run `simulate` accepts: bounds its time, ~1 µs a step


def _check_joint_value(joint: str, name: str, x: float) -> None:
    ok = {
        "lower": not np.isnan(x) and x < np.inf,
        "upper": not np.isnan(x) and x > -np.inf,
        "effort": x > 0.0,  # inf: no limit
        "velocity": not np.isnan(x),
        "damping": np.isfinite(x) and x >= 0.0,
        "friction": np.isfinite(x) and x >= 0.0,
    }[name]
    if not ok:
        need = {"effort": "> 0 (inf: none)", "damping": "finite, >= 0", "friction": "finite, >= 0"}
        raise InputError(
            f"joint {joint!r}: {name} {x:g} is not a valid value"
            + (f" (must be {need[name]})" if name in need else "")
        )


@dataclass(frozen=True)
class SimConfig:
    """Controller and integrator settings: PD gains [N·m/rad, N·m·s/rad] and time step [s]."""

    kp: np.ndarray
    kd: np.ndarray
    dt: float = DEFAULT_DT  # [s]
    integrator: Integrator = "euler"
    gravity_comp: bool = False

    def __post_init__(self) -> None:
        for name in ("kp", "kd"):
            g = np.asarray(getattr(self, name), dtype=float)
            if not (np.all(np.isfinite(g)) and np.all(g >= 0.0)):
                raise InputError(f"{name} gains must be finite and >= 0, got {g.tolist()}")
        time_step(self.dt, "SimConfig.dt")
        if self.integrator not in INTEGRATORS:
            raise InputError(
                f"unknown integrator {self.integrator!r}; valid: {', '.join(INTEGRATORS)}"
            )


@dataclass(frozen=True)
class SimResult:
    """One run: the states kept (`steps` says which) and statistics over every state."""

    joint_names: tuple[str, ...]
    steps: int  # steps of the run (states 0..steps)
    dt: float
    integrator: Integrator
    step: np.ndarray  # (K,) int: the states kept, by step
    t: np.ndarray  # (K,) their times [s]
    q: np.ndarray  # (K, n)
    v: np.ndarray
    q_ref: np.ndarray
    v_ref: np.ndarray
    tau: np.ndarray  # (K, n) motor torque applied from each state (the last: the last step's)
    saturated: np.ndarray  # (K, n) bool: that torque is at the effort limit
    stop_active: np.ndarray  # (K, n) bool: a joint-stop constraint acted in that step
    stats: ro.Stats  # over every state of the run, kept or not
    settle_tol: float  # [rad or m] the band of stats.last_out
    wall_time: float  # [s] spent in the engine


def simulated(robot: Robot, joints: Sequence[str] | None = None) -> Robot:
    """`robot` with `joints` (all by default) movable, the others locked; checked for the engine.

    Every joint 1-DoF, its limits numbers and in order (`check_limits`).
    """
    robot = robot.reduced(list(joints)) if joints else robot
    model = robot.model
    for jid in range(1, model.njoints):
        j = model.joints[jid]
        if j.nv != 1 or j.nq not in (1, 2):
            raise InputError(
                f"joint {model.names[jid]!r} ({j.shortname()}) cannot be simulated: only "
                "revolute, continuous and prismatic joints are supported (leave it out of `joints` "
                "to lock it)",
                field="joints",
            )
    check_limits(robot)
    return robot


def check_limits(robot: Robot) -> None:
    """Refuse, naming the joint, limits that are not numbers or out of order.

    A NaN friction would freeze the joint and a NaN limit would silently mean "no stop".
    The simulated joints keep the model's (tree) order whatever `joints` says; a continuous
    joint's angle is unbounded (lower -inf, upper inf: no stops).
    """
    for name in LIMITS:
        for joint, x in zip(robot.names, getattr(robot, name), strict=True):
            _check_joint_value(joint, name, float(x))
    for joint, lo, hi in zip(robot.names, robot.lower, robot.upper, strict=True):
        if lo > hi:
            raise InputError(f"joint {joint!r}: lower limit {lo:g} is above upper {hi:g}")


def plant_of(robot: Robot, cfg: SimConfig, energy_max: float = np.inf) -> ro.Plant:
    """The rollout's plant: the robot's limits, the gains and settings of `cfg`."""
    vel = np.where((robot.velocity > 0) & np.isfinite(robot.velocity), robot.velocity, np.nan)
    vabort = np.where(np.isnan(vel), DEFAULT_VABORT, VEL_ABORT_FACTOR * vel)
    n = len(robot.names)
    return ro.Plant(
        model=robot.model,
        kp=np.broadcast_to(np.asarray(cfg.kp, dtype=float), (n,)),
        kd=np.broadcast_to(np.asarray(cfg.kd, dtype=float), (n,)),
        damping=robot.damping,
        friction=robot.friction,
        lower=robot.lower,
        upper=robot.upper,
        effort=robot.effort,
        vabort=vabort,
        gravity_comp=cfg.gravity_comp,
        dt=cfg.dt,
        integrator=cfg.integrator,
        energy_max=energy_max,
    )


def check_stability(robot: Robot, cfg: SimConfig, configurations: np.ndarray) -> None:
    """Refuse gains/dt the integrator cannot handle: `check`'s verdict for this loop.

    The verdict and its remedy come from armcli.analysis.verdict (Euler steps damping
    implicitly, RK4 explicitly).

    Raises UnstableLoopError, which names no option: the command says where dt came from.
    """
    qs = [robot.q(q) for q in configurations]
    lin = pdloop.linearise(robot, qs, gravity=not cfg.gravity_comp)
    pd = pdloop.PD.of(range(robot.model.nv), cfg.kp, cfg.kd, robot.damping)
    scheme: pdloop.Scheme = "rk4" if cfg.integrator == "rk4" else "implicit"
    verdicts.refuse_unstable(lin, pd, cfg.dt, scheme, robot.names, configurations.tolist())


@dataclass(frozen=True)
class Run:
    """One closed-loop run of a batch: a robot, its reference, start and settings."""

    robot: Robot
    reference: Reference
    q0: np.ndarray
    duration: float  # [s]
    cfg: SimConfig
    record: np.ndarray | None = None  # the steps whose states are kept (None: every step)


def simulate(
    robot: Robot,
    reference: Reference,
    q0: np.ndarray,
    duration: float,
    cfg: SimConfig,
    progress: Callable[[int, int], None] | None = None,
    *,
    record: np.ndarray | None = None,
) -> SimResult:
    """Run the closed loop from rest at `q0` for `duration` seconds.

    Keeps the states at the strictly increasing steps `record` (default: every step);
    `progress(steps_done, steps_total)` is called between chunks of steps.
    """
    return _run(Run(robot, reference, q0, duration, cfg, record), None, progress)


def simulate_batch(runs: Sequence[Run], threads: int = 1) -> list[SimResult | SimulationError]:
    """Many independent runs (each keeping its `record` steps): `simulate`'s results or errors.

    The engine releases the GIL, so `threads` > 1 runs them in parallel; each distinct
    model is handed to the engine once.
    """
    mod = native.require()
    compiled: dict[int, Any] = {}
    for r in runs:
        if id(r.robot.model) not in compiled:
            compiled[id(r.robot.model)] = native.compiled_model(mod, r.robot.model)

    def one(r: Run) -> SimResult | SimulationError:
        try:
            return _run(r, compiled[id(r.robot.model)], None)
        except SimulationError as exc:
            return exc

    if threads <= 1 or len(runs) <= 1:
        return [one(r) for r in runs]
    with ThreadPoolExecutor(max_workers=threads) as pool:
        return list(pool.map(one, runs))


def steps_of(duration: float, dt: float) -> int:
    """Steps a run of `duration` [s] takes at `dt` [s] (at least one)."""
    return max(1, round(duration / dt))


def _run(r: Run, compiled: Any, progress: Callable[[int, int], None] | None) -> SimResult:
    steps = steps_of(r.duration, r.cfg.dt)
    plant = plant_of(r.robot, r.cfg)
    plant = replace(plant, energy_max=_energy_max(r.robot, r.q0, plant.vabort))
    start = time.perf_counter()
    out = ro.run(
        plant,
        r.reference,
        np.asarray(r.q0, dtype=float),
        np.zeros(len(r.q0)),
        steps,
        record=r.record,
        settle_tol=SETTLE_TOL,
        compiled=compiled,
        progress=progress,
    )
    wall = time.perf_counter() - start
    if out.failure:
        _raise(r.robot, plant, out)
    tr = out.trace
    return SimResult(
        joint_names=r.robot.names,
        steps=steps,
        dt=r.cfg.dt,
        integrator=r.cfg.integrator,
        step=tr.step,
        t=tr.step * r.cfg.dt,
        q=tr.q,
        v=tr.v,
        q_ref=tr.q_ref,
        v_ref=tr.v_ref,
        tau=tr.tau,
        saturated=tr.saturated,
        stop_active=tr.stop,
        stats=out.stats,
        settle_tol=SETTLE_TOL,
        wall_time=wall,
    )


def _energy_max(robot: Robot, q0: np.ndarray, vabort: np.ndarray) -> float:
    """[J] A kinetic energy no run within the velocity limits reaches: a blow-up beyond it."""
    M = robot.mass_matrix(robot.q(q0))
    return float(0.5 * np.max(np.linalg.eigvalsh(M)) * np.sum(vabort**2))


def _raise(robot: Robot, plant: ro.Plant, r: ro.Rollout) -> None:
    joint = robot.names[r.fail_joint] if r.fail_joint >= 0 else None
    if r.failure == "nonfinite":
        msg, cause = (
            "the state became non-finite",
            "dt too large for the gains or a near-zero inertia",
        )
    elif r.failure == "velocity":
        lim = plant.vabort[r.fail_joint]
        msg = f"velocity exceeded {lim:g} (x{VEL_ABORT_FACTOR:g} the URDF velocity limit)"
        cause = "an unstable closed loop: gains too high for dt or the inertia, try a smaller --dt"
    else:
        msg = f"kinetic energy exceeded {plant.energy_max:.3g} J"
        cause = "energy injected by the controller: gains too high for dt, try a smaller --dt"
    raise SimulationError(
        f"simulation diverged: {msg}",
        time=r.fail_step * plant.dt,
        step=r.fail_step,
        joint=joint,
        cause=cause,
    )
