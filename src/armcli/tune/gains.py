"""The candidate gain vector `[kp_1..kp_n, kd_1..kd_n]`: one layout for every user.

The search samples it, the evaluator simulates it, the reports and `--write` read it
back per joint; each goes through these functions instead of slicing by hand.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray


def stack(kp: ArrayLike, kd: ArrayLike) -> NDArray[np.float64]:
    """The gain vector of per-joint `kp` [N·m/rad] and `kd` [N·m·s/rad] (same joint order)."""
    kp_a, kd_a = np.asarray(kp, dtype=float), np.asarray(kd, dtype=float)
    if kp_a.shape != kd_a.shape or kp_a.ndim != 1:
        raise ValueError(f"kp {kp_a.shape} and kd {kd_a.shape} must be equal-length vectors")
    return np.concatenate([kp_a, kd_a])


def split(gains: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(kp, kd) of a gain vector."""
    g = np.asarray(gains, dtype=float)
    n = len(g) // 2
    return g[:n], g[n:]


def of_joint(gains: ArrayLike, j: int) -> tuple[float, float]:
    """(kp, kd) of the joint at index `j`."""
    kp, kd = split(gains)
    return float(kp[j]), float(kd[j])


def by_joint(gains: ArrayLike, joints: Sequence[str]) -> dict[str, tuple[float, float]]:
    """Joint name -> (kp, kd), in the order of `joints`."""
    return {name: of_joint(gains, j) for j, name in enumerate(joints)}


def param_names(joints: Sequence[str]) -> list[str]:
    """The search's name for each entry of the vector: `kp:JOINT`, then `kd:JOINT`."""
    return [f"kp:{j}" for j in joints] + [f"kd:{j}" for j in joints]
