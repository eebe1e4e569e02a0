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
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.defaults import DEFAULT_DT
from armcli.errors import InputError, SimulationError
from armcli.sim import native
from armcli.sim import rollout as ro
from armcli.sim import stability as stab

VEL_ABORT_FACTOR = 10.0  # divergence when |v| exceeds this times the URDF velocity limit
DEFAULT_VABORT = 1000.0  # [rad/s or m/s] when the URDF gives no velocity limit
CHUNK_STEPS = {"native": 20_000, "python": 500}  # steps per call, for the progress bar


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
    backend: str
    wall_time: float  # [s] spent in the rollout


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
        if j.shortname() not in ro.JOINT_TYPES or j.nq != 1:
            raise InputError(
                f"joint {model.names[jid]!r} ({j.shortname()}) cannot be simulated: only "
                "revolute and prismatic joints are supported (lock it with --joints)",
                field="--joints",
            )
    order = list(model.names)[1:]  # simulated in model (tree) order whatever --joints says
    effort = np.array(model.effortLimit, dtype=float)
    effort = np.where((effort > 0) & np.isfinite(effort), effort, np.inf)
    return Arm(
        model=model,
        joint_names=tuple(order),
        lower=np.array(model.lowerPositionLimit, dtype=float),
        upper=np.array(model.upperPositionLimit, dtype=float),
        effort=effort,
        velocity=np.array(model.velocityLimit, dtype=float),
        damping=np.array(model.damping, dtype=float),
        friction=np.array(model.friction, dtype=float),
    )


def params_of(arm: Arm, cfg: SimConfig) -> np.ndarray:
    """Per-joint parameter rows in `rollout.PARAM_FIELDS` order."""
    vel = np.where((arm.velocity > 0) & np.isfinite(arm.velocity), arm.velocity, np.nan)
    vabort = np.where(np.isnan(vel), DEFAULT_VABORT, VEL_ABORT_FACTOR * vel)
    cols = [cfg.kp, cfg.kd, arm.damping, arm.friction, arm.lower, arm.upper, arm.effort, vabort]
    return np.ascontiguousarray(np.column_stack(cols), dtype=float)


def check_stability(arm: Arm, cfg: SimConfig, configurations: np.ndarray) -> None:
    """Refuse gains/dt the integrator cannot handle (the bound `check` reports), saying what would.

    Euler steps damping implicitly, as `check`'s implicit loop; RK4 is explicit.
    """
    import pinocchio as pin

    data = arm.model.createData()
    K, B = np.asarray(cfg.kp, float), np.asarray(cfg.kd, float) + arm.damping
    Ms = []
    for q in configurations:
        M = pin.crba(arm.model, data, q)
        Ms.append(np.triu(M) + np.triu(M, 1).T)
    controlled = list(range(arm.model.nv))
    scheme: stab.Scheme = "rk4" if cfg.integrator == "rk4" else "implicit"
    rho, k = stab.worst_radius(Ms, controlled, K, B, cfg.dt, scheme)
    if stab.is_stable(rho):
        return
    dt_ok = stab.largest_stable_dt([Ms[k]], controlled, K, B, scheme, cfg.dt)
    scale = stab.largest_stable_scale([Ms[k]], controlled, K, B, cfg.dt, scheme)
    what = "Kd + damping" if cfg.integrator == "rk4" else "Kp"
    hint = " or the default euler integrator" if cfg.integrator == "rk4" else ""
    raise InputError(
        f"the {cfg.integrator} integrator is unstable with these gains at dt = {cfg.dt:g} s "
        f"(closed-loop step spectral radius {rho:.3f} > 1 at "
        f"q = {np.round(configurations[k], 3).tolist()}); "
        f"{what} is too stiff for this inertia: use --dt <= {dt_ok:.3g} or gains scaled by "
        f"<= {scale:.3g}{hint}",
        field="--dt",
    )


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
    sub = 2 if cfg.integrator == "rk4" else 1
    t_ref = np.arange(sub * steps + 1) * (cfg.dt / sub)
    q_ref, v_ref = reference.sample(t_ref)
    ref = np.ascontiguousarray(np.hstack([q_ref, v_ref]))
    lib = native.load() if cfg.backend in ("auto", "native") else None
    if cfg.backend == "native" and lib is None:
        raise InputError(
            f"the compiled simulator is not built ({native.why_missing()}); run `make native`"
        )
    run = (lambda *a: native.rollout(lib, *a)) if lib is not None else ro.rollout_python
    parts: list[ro.Rollout] = []
    q, v = np.array(q0, dtype=float), np.zeros(len(q0))
    start = time.perf_counter()
    chunk = CHUNK_STEPS["native" if lib is not None else "python"]
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
    backend = "native" if lib is not None else "python"
    return _result(arm, cfg, parts, q_ref[::sub], v_ref[::sub], backend, wall)


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
    import pinocchio as pin

    M = pin.crba(arm.model, arm.model.createData(), np.asarray(q0, dtype=float))
    M = np.triu(M) + np.triu(M, 1).T
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
