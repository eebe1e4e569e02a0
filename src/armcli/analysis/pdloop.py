"""The PD loop that the stability bound judges, as data.

Its gains (`PD`), the arm linearised at its operating points (`linearise`), and how the
loop is stepped (`Scheme`); `analysis.stability` decides whether that is stable.
"""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.robot.model import Robot

Scheme = Literal["explicit", "implicit", "rk4"]
"""How the PD loop is stepped: semi-implicit Euler with damping explicit (a torque loop as
in Gazebo's effort controllers) or implicit (armcli's simulator), or RK4 (explicit)."""
Scaled = Literal["Kp", "Kd", "Kp and Kd"]  # which gains a GainScale scales, in words

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Linearised:
    """The arm at its operating points: symmetric M(q) and gravity's stiffness G(q)."""

    M: Array  # (S, nv, nv) [kg·m²]
    G: Array  # (S, nv, nv) dg/dq [N·m/rad]; zeros with gravity compensation

    def __len__(self) -> int:
        return int(self.M.shape[0])


@dataclass(frozen=True)
class PD:
    """PD gains on the controlled velocity indices `idx` (the others move freely)."""

    idx: tuple[int, ...]
    kp: Array  # [N·m/rad]
    kd: Array  # [N·m·s/rad]
    damping: Array  # joint viscous damping of the controlled joints [N·m·s/rad]

    @staticmethod
    def of(idx: Sequence[int], kp: ArrayLike, kd: ArrayLike, damping: ArrayLike) -> PD:
        """Gains as float arrays (one entry per controlled joint)."""
        arr = [np.asarray(x, dtype=float).reshape(-1) for x in (kp, kd, damping)]
        return PD(tuple(int(i) for i in idx), arr[0], arr[1], arr[2])

    def scaled(self, kp: float, kd: float) -> PD:
        """The same joints with Kp and Kd multiplied by `kp` and `kd` (damping is physical)."""
        return PD(self.idx, self.kp * kp, self.kd * kd, self.damping)


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run numpy's linear algebra on one thread inside the block.

    The analysis factors many small matrices; a multi-threaded BLAS spends more on waking
    its threads than on the work (a 129 x 129 Cholesky: 0.12 ms on one thread, ~10 ms with
    OpenBLAS's threads on a busy 2-core machine), and under `tune`'s threads it competes
    with the rollouts. Without threadpoolctl the block runs as is.
    """
    controller = _blas_controller()
    if controller is None:  # pragma: no cover - optional speed-up
        yield
        return
    with controller.limit(limits=1, user_api="blas"):
        yield


@functools.cache
def _blas_controller() -> Any:
    """The loaded BLAS libraries as threadpoolctl finds them, once per process.

    Finding them walks every loaded shared object (~0.1 s CPU on a busy machine: a fifth
    of `plan --base --execute`'s drive); numpy's BLAS is loaded before the first call.
    """
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover - optional speed-up
        return None
    return ThreadpoolController()


def linearise(robot: Robot, configurations: Sequence[Any], *, gravity: bool = True) -> Linearised:
    """M(q) (CRBA, symmetric) and G(q) = dg/dq at each Pinocchio configuration.

    `gravity=False` for a loop that compensates g(q) (then G = 0).
    """
    nv = robot.model.nv
    Ms, Gs = [], []
    for q in configurations:
        q = np.asarray(q, dtype=float)
        Ms.append(robot.mass_matrix(q))
        Gs.append(robot.gravity_stiffness(q) if gravity else np.zeros((nv, nv)))
    return Linearised(np.array(Ms, dtype=float), np.array(Gs, dtype=float))
