"""The compiled rollout (the `armcli.sim._rollout` extension) and the choice of engine.

The extension is built at install time (`pip install .`, `make install`; CMakeLists.txt)
against the Pinocchio of the `pin` wheel; nothing compiles at run time. Where it is
missing (an sdist installed without a compiler), `load()` returns None with the reason
in `why_missing()` and callers use the identical Python loop in `rollout.py`.

The extension releases the GIL for the whole rollout, so `rollout_batch` runs many
rollouts (gain sets, models, initial states) on threads in parallel.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from types import ModuleType
from typing import Any

import numpy as np

from armcli.sim import rollout as ro

ABI_VERSION = 3
_UNALIGNED = (
    "JointModelRevoluteUnaligned",
    "JointModelPrismaticUnaligned",
    "JointModelRevoluteUnboundedUnaligned",
)
_state: dict[str, Any] = {}


def load() -> ModuleType | None:
    """The extension module, or None when it is not installed (or ARMCLI_NO_NATIVE is set)."""
    if "module" not in _state:
        _state["module"], _state["why"] = _import()
    mod: ModuleType | None = _state["module"]
    return mod


def _import() -> tuple[ModuleType | None, str]:
    if os.environ.get("ARMCLI_NO_NATIVE"):
        return None, "ARMCLI_NO_NATIVE is set"
    import pinocchio  # noqa: F401  (loads libpinocchio_default before the extension)

    try:
        from armcli.sim import _rollout  # type: ignore[attr-defined]
    except ImportError as exc:
        return None, f"the armcli.sim._rollout extension is not installed ({exc})"
    if getattr(_rollout, "ABI_VERSION", None) != ABI_VERSION:
        return None, "the installed armcli.sim._rollout extension is stale: reinstall armcli"
    return _rollout, ""


def why_missing() -> str:
    """Why `load()` returned None, for the one-line notice."""
    load()
    why: str = _state["why"]
    return why


def engine_name(mod: ModuleType | None) -> str:
    """The engine `load()`'s result runs: "native" (compiled) or "python"."""
    return "native" if mod is not None else "python"


def model_arrays(model: Any) -> dict[str, np.ndarray]:
    """The model as flat arrays the C++ side rebuilds it from (one-dof joints only)."""
    n = model.njoints - 1
    out = {
        "jtype": np.zeros(n, dtype=np.int32),
        "parent": np.zeros(n, dtype=np.int32),
        "placement": np.zeros((n, 12)),
        "axis": np.zeros((n, 3)),
        "inertia": np.zeros((n, 13)),
        "gravity": np.array(model.gravity.linear, dtype=float),
    }
    for i in range(n):
        jid = i + 1
        j = model.joints[jid]
        out["jtype"][i] = ro.JOINT_TYPES[j.shortname()]
        out["parent"][i] = model.parents[jid]
        M = model.jointPlacements[jid]
        out["placement"][i] = np.concatenate([M.rotation.reshape(-1), M.translation])
        if j.shortname() in _UNALIGNED:  # the generic JointModel has no axis; the concrete one has
            out["axis"][i] = j.extract().axis
        Y = model.inertias[jid]
        out["inertia"][i] = np.concatenate([[Y.mass], Y.lever, Y.inertia.reshape(-1)])
    return out


def compiled_model(mod: ModuleType, model: Any) -> Any:
    """The extension's copy of a pinocchio.Model (build once, reuse across rollouts)."""
    a = model_arrays(model)
    c = np.ascontiguousarray
    return mod.build_model(
        a["jtype"], a["parent"], c(a["placement"]), c(a["axis"]), c(a["inertia"]), a["gravity"]
    )


@dataclass(frozen=True)
class Job:
    """One rollout of a batch: any plant (model, gains, dt), initial state and reference."""

    plant: ro.Plant
    q0: np.ndarray
    v0: np.ndarray
    ref: np.ndarray
    compiled: Any = None  # compiled_model(...) of plant.model, built on demand when None


def rollout(
    mod: ModuleType, plant: ro.Plant, q0: np.ndarray, v0: np.ndarray, ref: np.ndarray
) -> ro.Rollout:
    """One rollout through the extension; same contract as `rollout.rollout_python`."""
    return _run(mod, Job(plant, q0, v0, ref))


def rollout_batch(
    mod: ModuleType, jobs: Sequence[Job], threads: int | None = None
) -> list[ro.Rollout]:
    """Independent rollouts, in order, on `threads` threads (default: one per CPU).

    The extension releases the GIL, so the rollouts run in parallel.
    """
    models: dict[int, Any] = {}  # each distinct pinocchio.Model is converted once
    for j in jobs:
        if j.compiled is None and id(j.plant.model) not in models:
            models[id(j.plant.model)] = compiled_model(mod, j.plant.model)
    ready = [
        j if j.compiled is not None else replace(j, compiled=models[id(j.plant.model)])
        for j in jobs
    ]
    workers = max(1, min(threads or os.cpu_count() or 1, len(jobs)))
    if workers == 1:
        return [_run(mod, j) for j in ready]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(lambda j: _run(mod, j), ready))


def _run(mod: ModuleType, job: Job) -> ro.Rollout:
    plant = job.plant
    n = plant.model.nv
    steps = ro.steps_of(plant, job.ref)
    Q = np.full((steps + 1, n), np.nan)
    V = np.full((steps + 1, n), np.nan)
    T = np.full((steps, n), np.nan)
    F = np.zeros((steps, n), dtype=np.uint8)
    compiled = job.compiled if job.compiled is not None else compiled_model(mod, plant.model)
    c = np.ascontiguousarray
    fail_step, fail_joint, fail_code = mod.rollout(
        compiled, c(plant.params, dtype=float), plant.gravity_comp, plant.dt, plant.integrator,
        plant.energy_max, c(job.q0, dtype=float), c(job.v0, dtype=float),
        c(job.ref, dtype=float), Q, V, T, F,
    )  # fmt: skip
    return ro.Rollout(Q, V, T, F, int(fail_step), int(fail_joint), int(fail_code))


if __name__ == "__main__":  # `python -m armcli.sim.native`: which engine this install has
    import sys

    if load() is None:
        print(f"armcli: compiled rollout unavailable: {why_missing()}", file=sys.stderr)
        raise SystemExit(1)
    print(f"armcli: compiled rollout {load()}")
