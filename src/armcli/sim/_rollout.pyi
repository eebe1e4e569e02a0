"""Types of the compiled simulator `armcli.sim._rollout` (bindings in _native/rollout.cpp).

Written from nanobind's stubgen output, with the dictionaries and tuples spelled out. Keep it
in step with the `NB_MODULE` block at the end of rollout.cpp.
"""

from typing import Any

import numpy as np
from numpy.typing import NDArray

_F64 = NDArray[np.float64]

SOURCE_SHA256: str
FAIL_NONE: int
FAIL_NONFINITE: int
FAIL_VELOCITY: int
FAIL_ENERGY: int

class Model:
    @property
    def nv(self) -> int: ...
    @property
    def nq(self) -> int: ...

def load_model(data: bytes) -> Model:
    """The pinocchio.Model serialised by Model.saveToBinary."""

class Plant: ...

def plant(
    model: Model,
    *,
    kp: _F64,
    kd: _F64,
    damping: _F64,
    friction: _F64,
    lower: _F64,
    upper: _F64,
    effort: _F64,
    vabort: _F64,
    gravity_comp: bool,
    dt: float,
    integrator: str,
    energy_max: float,
) -> Plant: ...

class Reference:
    def sample(self, t: _F64) -> tuple[_F64, _F64]:
        """q_ref, v_ref at times t (the piece holding each t)."""

def reference(knots: _F64, coeffs: _F64, final: _F64) -> Reference: ...

class Rollout:
    @property
    def step(self) -> int: ...
    @property
    def q(self) -> _F64: ...
    @property
    def v(self) -> _F64: ...
    def advance(self, steps: int) -> tuple[int, int, int]:
        """Run up to `steps` more steps without the GIL; (fail_step, fail_joint, fail_code)."""
    def records(self) -> dict[str, NDArray[Any]]:
        """The requested states (copies): step, q, v, q_ref, v_ref, tau, saturated, stop."""
    def statistics(self) -> dict[str, Any]:
        """Running tracking statistics over every state (states, steps: int; the rest arrays)."""

def rollout(
    plant: Plant,
    reference: Reference,
    q0: _F64,
    v0: _F64,
    steps: int,
    record: NDArray[np.int64],
    settle_tol: float,
) -> Rollout: ...
