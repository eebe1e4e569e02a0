"""Types of the compiled planner `armcli.plan._planner` (bindings in _native/module.cpp).

Written from the `NB_MODULE` block at the end of module.cpp; keep the two in step.
"""

from typing import Any

import numpy as np
from numpy.typing import NDArray

_F64 = NDArray[np.float64]
_I32 = NDArray[np.int32]
_B = NDArray[np.bool_]

SOURCE_SHA256: str

class Scene:
    @property
    def n(self) -> int: ...
    @property
    def npairs(self) -> int: ...
    @property
    def queries(self) -> int: ...
    @property
    def states(self) -> int: ...
    @property
    def lever(self) -> _F64: ...
    @property
    def pair_lever(self) -> _F64: ...
    def q(self, x: _F64) -> _F64: ...
    def set_margins(self, margins: _F64) -> None: ...
    def colliding(self, x: _F64, margin: float) -> list[int]: ...
    def first_collision(self, x: _F64, every_pair: bool) -> int: ...
    def free(self, x: _F64) -> bool: ...
    def free_many(self, X: _F64) -> _B: ...
    def motion_free(self, a: _F64, b: _F64, step: float) -> bool: ...
    def motion_free_many(self, A: _F64, B: _F64, step: float) -> _B: ...
    def plan(
        self,
        start: _F64,
        goal: _F64,
        *,
        range: float,
        goal_bias: float,
        step: float,
        timeout: float,
        seed: int,
        threads: int,
        attempt_nodes: int,
        bridge: float = 0.0,
        bridge_sigma: float = 0.3,
        lazy_step: float = 0.0,
    ) -> tuple[_F64 | None, dict[str, Any]]: ...
    def shortcut(self, path: _F64, step: float, seed: int, tries: int, patience: int) -> _F64: ...
    def sweep(self, X: _F64) -> tuple[int, int, int, int]: ...
    def inverse_dynamics(self, X: _F64, XD: _F64, XDD: _F64, iv: list[int]) -> _F64: ...
    def time_polyline(
        self,
        W: _F64,
        velocity: _F64,
        acceleration: _F64,
        effort: _F64,
        iv: list[int],
        grid: int,
        rate: float,
        blend: float = 0.0,
        step: float = 0.02,
    ) -> int | tuple[_F64, _F64, _F64, _F64]: ...

def scene(
    model: bytes,
    geometry: bytes,
    q_template: _F64,
    joint: _I32,
    iq: _I32,
    iv: _I32,
    continuous: _B,
    offset: _F64,
    coeff: _F64,
    pair_a: _I32,
    pair_b: _I32,
    moving: _B,
    body: _I32,
    lower: _F64,
    upper: _F64,
) -> Scene: ...
def spline(t: _F64, y: _F64) -> tuple[_F64, _F64]: ...
def bisection_order(n: int) -> list[int]: ...
