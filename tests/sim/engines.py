"""The compiled engine for tests: required wherever a C++ compiler exists.

A missing `armcli.sim._rollout` extension on a machine that could have built it means the
build is broken; the tests say so instead of skipping (only a machine without a compiler
skips, with the reason). Also: running a plant held at a constant reference.
"""

from __future__ import annotations

import shutil
from types import ModuleType

import numpy as np
import pytest

from armcli.sim import native
from armcli.sim import rollout as ro
from armcli.trajectory.reference import Reference


def has_compiler() -> bool:
    return any(shutil.which(c) for c in ("c++", "g++", "clang++"))


def require_native() -> ModuleType:
    mod = native.load()
    if mod is not None:
        return mod
    if has_compiler():
        pytest.fail(
            f"compiled engine missing although a C++ compiler exists: {native.why_missing()}"
        )
    pytest.skip(f"no C++ compiler: {native.why_missing()}")


def hold(q: np.ndarray) -> Reference:
    """The reference q_ref = q, v_ref = 0 at all times (one point at t = 0)."""
    q = np.asarray(q, dtype=float)
    return Reference(knots=np.zeros(1), coeffs=np.zeros((0, 6, q.shape[0])), final=q)


def run_held(
    plant: ro.Plant, q0: list[float] | np.ndarray, v0: list[float] | np.ndarray, steps: int,
    q_hold: list[float] | np.ndarray | None = None,
) -> ro.Rollout:  # fmt: skip
    """`steps` steps from (q0, v0) with the reference held at `q_hold` (default: zero)."""
    require_native()
    n = len(q0)
    target = np.zeros(n) if q_hold is None else np.asarray(q_hold, dtype=float)
    return ro.run(plant, hold(target), np.asarray(q0, float), np.asarray(v0, float), steps)
