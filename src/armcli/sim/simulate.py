"""Simulate an arm under PD control along a reference: setup, stability check, results.

The step itself (implicit damping, friction, joint stops) is in `rollout.py`. Here:
which joints move (others are locked), the per-joint parameters from the URDF, the
linear stability check that refuses gains the integrator cannot handle, and turning a
rollout into a `SimResult` or a `SimulationError` that says when, where and why.

Stability bound: with Kd and damping implicit, semi-implicit Euler stays stable for any
Kd, D >= 0; the remaining bound is on Kp. For one joint of inertia m it is
dt² Kp < 4 m + 2 dt (Kd + D); for the arm it is checked exactly on the linearised
closed loop (spectral radius of the step map <= 1) at the start and at every trajectory
point. RK4 treats everything explicitly and is bounded by dt (Kd + D) λ_max(M⁻¹) < ~2.8.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from armcli.defaults import DEFAULT_DT
from armcli.errors import InputError, SimulationError
from armcli.sim import native
from armcli.sim import rollout as ro
from armcli.sim import stability as stab
from armcli.sim import verdict as verdicts
from armcli.urdf.pinocchio import mass_matrix

VEL_ABORT_FACTOR = 10.0  # divergence when |v| exceeds this times the URDF velocity limit
DEFAULT_VABORT = 1000.0  # [rad/s or m/s] when the URDF gives no velocity limit
# Steps per rollout call, for the progress bar; the same for both engines, since each call
# starts the friction solver's warm start afresh.
CHUNK_STEPS = {"native": 5_000, "python": 5_000}


@dataclass(frozen=True)
class Arm:
    """A fixed-base model reduced to the simulated one-dof joints, plus its URDF limits."""

    model: Any  # pinocchio.Model
    joint_names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    effort: np.ndarray  # [N·m or N]; inf when the URDF gives none
    velocity: np.ndarray
    damping: np.ndarray
    friction: np.ndarray


@dataclass(frozen=True)
class SimConfig:
    """Controller and integrator settings: PD gains [N·m/rad, N·m·s/rad] and time step [s]."""

    kp: np.ndarray
    kd: np.ndarray
    dt: float = DEFAULT_DT  # [s]
    integrator: str = "euler"
    gravity_comp: bool = False
    backend: str = "auto"  # "auto" | "native" | "python"


@dataclass(frozen=True)
class SimResult:
    """One rollout: time [s], states, references and motor torques [N·m] at every step."""

    joint_names: tuple[str, ...]
    t: np.ndarray  # (N + 1,) [s]
    q: np.ndarray  # (N + 1, n)
    v: np.ndarray
    q_ref: np.ndarray
    v_ref: np.ndarray
    tau: np.ndarray  # (N, n) motor torque during each step
    saturated: np.ndarray  # (N, n) bool
    stop_active: np.ndarray  # (N, n) bool: a joint-stop constraint acted in the step
    dt: float
    integrator: str
    backend: str  # the engine that ran: "native" (compiled) or "python"
    wall_time: float  # [s] spent in the rollout
    notice: str | None = None  # why `auto` fell back to the Python engine


def arm_from_model(model: Any, joints: Sequence[str] | None = None) -> Arm:
    """Keep `joints` (all by default) movable and lock the others at their neutral value."""
    import pinocchio as pin

    names = list(model.names)[1:]
    chosen = list(joints) if joints else names
    for name in chosen:
        if name not in names:
            raise InputError(f"unknown joint {name!r}; valid: {', '.join(names)}", field="--joints")
    if len(set(chosen)) != len(chosen):
        raise InputError("a joint is listed twice", field="--joints")
    lock = [model.getJointId(nm) for nm in names if nm not in chosen]
    if lock:
        model = pin.buildReducedModel(model, lock, pin.neutral(model))
    for jid in range(1, model.njoints):
        j = model.joints[jid]
        if j.shortname() not in ro.JOINT_TYPES or j.nv != 1:
            raise InputError(
                f"joint {model.names[jid]!r} ({j.shortname()}) cannot be simulated: only "
                "revolute, continuous and prismatic joints are supported (lock it with --joints)",
                field="--joints",
            )
    order = list(model.names)[1:]  # simulated in model (tree) order whatever --joints says
    iq = [model.idx_qs[j] for j in range(1, model.njoints)]
    bounded = np.array([model.nqs[j] == 1 for j in range(1, model.njoints)])
    # a continuous joint's angle is unbounded: no stops (Pinocchio's limits are on cos, sin)
    lower = np.where(bounded, np.array(model.lowerPositionLimit, dtype=float)[iq], -np.inf)
    upper = np.where(bounded, np.array(model.upperPositionLimit, dtype=float)[iq], np.inf)
    effort = np.array(model.effortLimit, dtype=float)
    effort = np.where((effort > 0) & np.isfinite(effort), effort, np.inf)
    return Arm(
        model=model,
        joint_names=tuple(order),
        lower=lower,
        upper=upper,
        effort=effort,
        velocity=np.array(model.velocityLimit, dtype=float),
        damping=np.array(model.damping, dtype=float),
        friction=np.array(model.friction, dtype=float),
    )


def configuration(model: Any, q: np.ndarray) -> np.ndarray:
    """Pinocchio's configuration vector of the joint positions `q` [rad or m], one per joint.

    The simulator's state holds a continuous joint's angle, unbounded; Pinocchio holds
    (cos, sin) of it (nq = 2, nv = 1).
    """
    q = np.asarray(q, dtype=float)
    if model.nq == model.nv:
        return q
    out = np.empty(model.nq)
    for i, jid in enumerate(range(1, model.njoints)):
        k = model.idx_qs[jid]
        if model.nqs[jid] == 2:
            out[k], out[k + 1] = np.cos(q[i]), np.sin(q[i])
        else:
            out[k] = q[i]
    return out


def params_of(arm: Arm, cfg: SimConfig) -> np.ndarray:
    """Per-joint parameter rows in `rollout.PARAM_FIELDS` order."""
    vel = np.where((arm.velocity > 0) & np.isfinite(arm.velocity), arm.velocity, np.nan)
    vabort = np.where(np.isnan(vel), DEFAULT_VABORT, VEL_ABORT_FACTOR * vel)
    cols = [cfg.kp, cfg.kd, arm.damping, arm.friction, arm.lower, arm.upper, arm.effort, vabort]
    return np.ascontiguousarray(np.column_stack(cols), dtype=float)


def check_stability(arm: Arm, cfg: SimConfig, configurations: np.ndarray) -> None:
    """Refuse gains/dt the integrator cannot handle: `check`'s verdict for this loop.

    The verdict and its remedy come from armcli.sim.verdict (Euler steps damping
    implicitly, RK4 explicitly).

    Raises UnstableLoopError, which names no option: the command says where dt came from.
    """
    qs = [configuration(arm.model, q) for q in configurations]
    lin = stab.linearise(arm.model, qs, gravity=not cfg.gravity_comp)
    pd = stab.PD.of(range(arm.model.nv), cfg.kp, cfg.kd, arm.damping)
    scheme: stab.Scheme = "rk4" if cfg.integrator == "rk4" else "implicit"
    verdicts.refuse_unstable(lin, pd, cfg.dt, scheme, arm.joint_names, configurations.tolist())


def simulate(
    arm: Arm,
    reference: Any,  # interpolation.Reference
    q0: np.ndarray,
    duration: float,
    cfg: SimConfig,
    progress: Callable[[int, int], None] | None = None,
) -> SimResult:
    """Run the closed loop from rest at `q0` for `duration` seconds."""
    steps = max(1, round(duration / cfg.dt))
    params = params_of(arm, cfg)
    plant = ro.Plant(
        arm.model, params, cfg.gravity_comp, cfg.dt, cfg.integrator, _energy_max(arm, q0, params)
    )
    sub = ro.rows_per_step(cfg.integrator)
    ref, q_ref, v_ref = sample_reference(reference, steps, cfg.dt, cfg.integrator)
    mod = native.load() if cfg.backend in ("auto", "native") else None
    if cfg.backend == "native" and mod is None:
        raise InputError(f"the compiled simulator is unavailable: {native.why_missing()}")
    notice = None
    if cfg.backend == "auto" and mod is None:
        notice = f"compiled engine unavailable ({native.why_missing()}); using the Python loop"
    compiled = native.compiled_model(mod, arm.model) if mod is not None else None

    def run(p: ro.Plant, q: np.ndarray, v: np.ndarray, r: np.ndarray) -> ro.Rollout:
        if mod is None:
            return ro.rollout_python(p, q, v, r)
        return native.rollout_batch(mod, [native.Job(p, q, v, r, compiled)])[0]

    parts: list[ro.Rollout] = []
    q, v = np.array(q0, dtype=float), np.zeros(len(q0))
    start = time.perf_counter()
    chunk = CHUNK_STEPS[native.engine_name(mod)]
    for k0 in range(0, steps, chunk):
        k1 = min(steps, k0 + chunk)
        r = run(plant, q, v, ref[sub * k0 : sub * k1 + 1])
        parts.append(r)
        if r.fail_step >= 0:
            _raise(arm, params, plant, r, k0)
        q, v = r.q[-1], r.v[-1]
        if progress is not None:
            progress(k1, steps)
    wall = time.perf_counter() - start
    res = _result(arm, cfg, parts, q_ref, v_ref, native.engine_name(mod), wall)
    return replace(res, notice=notice)


@dataclass(frozen=True)
class Run:
    """One closed-loop run of a batch: an arm, its reference, start and settings."""

    arm: Arm
    reference: Any  # reference.Reference
    q0: np.ndarray
    duration: float  # [s]
    cfg: SimConfig
    # sample_reference(reference, steps, cfg.dt, cfg.integrator), when the caller already
    # has it: `armcli tune` samples each case once for all its candidates
    sampled: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None


@dataclass
class _Progress:
    """One run of a batch between chunks: its plant and tables, state so far, outcome."""

    plant: ro.Plant
    params: np.ndarray
    ref: np.ndarray
    q_ref: np.ndarray
    v_ref: np.ndarray
    steps: int
    q: np.ndarray
    v: np.ndarray
    parts: list[ro.Rollout]
    error: SimulationError | None = None


def _start(r: Run) -> _Progress:
    steps = max(1, round(r.duration / r.cfg.dt))
    params = params_of(r.arm, r.cfg)
    energy = _energy_max(r.arm, r.q0, params)
    plant = ro.Plant(r.arm.model, params, r.cfg.gravity_comp, r.cfg.dt, r.cfg.integrator, energy)
    ref, q_ref, v_ref = (
        r.sampled
        if r.sampled is not None
        else sample_reference(r.reference, steps, r.cfg.dt, r.cfg.integrator)
    )
    q0 = np.array(r.q0, dtype=float)
    return _Progress(plant, params, ref, q_ref, v_ref, steps, q0, np.zeros(len(q0)), [])


def simulate_batch(runs: Sequence[Run]) -> list[SimResult | SimulationError]:
    """Many independent runs; each result equals `simulate`'s (or its SimulationError).

    With the compiled engine, the same chunk of every run goes to the extension in one
    `native.rollout_batch` call on one thread (callers such as `armcli tune` parallelise
    across batches); without it, the runs go through `simulate` one by one.
    """
    mod = native.load()
    if not runs or mod is None or any(r.cfg.backend == "python" for r in runs):
        return [_simulate_or_error(r) for r in runs]
    state = [_start(r) for r in runs]
    models = {id(r.arm.model): r.arm.model for r in runs}  # each model compiled once
    compiled = {key: native.compiled_model(mod, m) for key, m in models.items()}
    chunk = CHUNK_STEPS[native.engine_name(mod)]
    start = time.perf_counter()
    for k0 in range(0, max(s.steps for s in state), chunk):
        live = [i for i, s in enumerate(state) if k0 < s.steps and s.error is None]
        jobs = []
        for i in live:
            s, sub = state[i], ro.rows_per_step(runs[i].cfg.integrator)
            table = s.ref[sub * k0 : sub * min(s.steps, k0 + chunk) + 1]
            jobs.append(native.Job(s.plant, s.q, s.v, table, compiled[id(s.plant.model)]))
        for i, r in zip(live, native.rollout_batch(mod, jobs, threads=1), strict=True):
            s = state[i]
            s.parts.append(r)
            if r.fail_step >= 0:
                try:
                    _raise(runs[i].arm, s.params, s.plant, r, k0)
                except SimulationError as exc:
                    s.error = exc
                continue
            s.q, s.v = r.q[-1], r.v[-1]
    wall = (time.perf_counter() - start) / max(1, len(runs))
    name = native.engine_name(mod)
    return [
        s.error
        if s.error is not None
        else _result(r.arm, r.cfg, s.parts, s.q_ref, s.v_ref, name, wall)
        for r, s in zip(runs, state, strict=True)
    ]


def _simulate_or_error(r: Run) -> SimResult | SimulationError:
    try:
        return simulate(r.arm, r.reference, r.q0, r.duration, r.cfg)
    except SimulationError as exc:
        return exc


def sample_reference(
    reference: Any, steps: int, dt: float, integrator: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rollout's reference table, sampled once, and q_ref, v_ref at the step times.

    RK4 gets three rows per step (t, t + dt/2, t + dt) from the polynomial piece holding
    the step's midpoint: at a knot the step's last stage sees the left limit of the
    segment it integrates, not the next segment's velocity, which would cost RK4 its order.
    """
    t = np.arange(steps + 1) * dt
    q_ref, v_ref = reference.sample(t)
    if integrator != "rk4":
        return np.ascontiguousarray(np.hstack([q_ref, v_ref])), q_ref, v_ref
    offsets = np.array([0.0, 0.5, 1.0]) * dt
    ts = (t[:-1, None] + offsets).reshape(-1)
    mids = np.repeat(t[:-1] + 0.5 * dt, ro.RK4_ROWS)
    qs, vs = reference.sample(ts, segment_time=mids)
    table = np.vstack([np.hstack([qs, vs]), np.hstack([q_ref[-1:], v_ref[-1:]])])
    return np.ascontiguousarray(table), q_ref, v_ref


def _result(
    arm: Arm,
    cfg: SimConfig,
    parts: list[ro.Rollout],
    q_ref: np.ndarray,
    v_ref: np.ndarray,
    backend: str,
    wall: float,
) -> SimResult:
    """Stitch the chunks (each repeats the previous chunk's last state as its first row)."""
    flags = np.vstack([p.flags for p in parts])
    return SimResult(
        joint_names=arm.joint_names,
        t=np.arange(q_ref.shape[0]) * cfg.dt,
        q=np.vstack([parts[0].q[:1]] + [p.q[1:] for p in parts]),
        v=np.vstack([parts[0].v[:1]] + [p.v[1:] for p in parts]),
        q_ref=q_ref,
        v_ref=v_ref,
        tau=np.vstack([p.tau for p in parts]),
        saturated=(flags & ro.FLAG_SATURATED) > 0,
        stop_active=(flags & ro.FLAG_STOP) > 0,
        dt=cfg.dt,
        integrator=cfg.integrator,
        backend=backend,
        wall_time=wall,
    )


def _energy_max(arm: Arm, q0: np.ndarray, params: np.ndarray) -> float:
    M = mass_matrix(arm.model, arm.model.createData(), configuration(arm.model, q0))
    return float(0.5 * np.max(np.linalg.eigvalsh(M)) * np.sum(params[:, ro.VABORT] ** 2))


def _raise(arm: Arm, params: np.ndarray, plant: ro.Plant, r: ro.Rollout, k0: int) -> None:
    step = k0 + r.fail_step
    joint = arm.joint_names[r.fail_joint] if r.fail_joint >= 0 else None
    if r.fail_code == ro.FAIL_NONFINITE:
        msg, cause = (
            "the state became non-finite",
            "dt too large for the gains or a near-zero inertia",
        )
    elif r.fail_code == ro.FAIL_VELOCITY:
        lim = params[r.fail_joint, ro.VABORT]
        msg = f"velocity exceeded {lim:g} (x{VEL_ABORT_FACTOR:g} the URDF velocity limit)"
        cause = "an unstable closed loop: gains too high for dt or the inertia, try a smaller --dt"
    else:
        msg = f"kinetic energy exceeded {plant.energy_max:.3g} J"
        cause = "energy injected by the controller: gains too high for dt, try a smaller --dt"
    raise SimulationError(
        f"simulation diverged: {msg}", time=step * plant.dt, step=step, joint=joint, cause=cause
    )
