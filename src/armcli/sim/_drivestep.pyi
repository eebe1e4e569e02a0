"""Types of the compiled drive steps `armcli.sim._drivestep` (bindings in _native/drivestep.cpp).

Keep it in step with the `NB_MODULE` block at the end of drivestep.cpp.
"""

import numpy as np
from numpy.typing import NDArray

SOURCE_SHA256: str

class Stepper:
    def advance(self, k0: int, k1: int, rows: NDArray[np.int64], wl: float, wr: float) -> None:
        """Steps k0 .. k1 - 1: rotors at (wl, wr), the arm at `rows`."""

def stepper(
    step: int,
    m: int,
    d: int,
    qpos: NDArray[np.float64],
    qvel: NDArray[np.float64],
    ctrl: NDArray[np.float64],
    sensordata: NDArray[np.float64],
    qfrc_constraint: NDArray[np.float64],
    rotor: NDArray[np.int64],
    wheel_dof: NDArray[np.int64],
    wheel_force: NDArray[np.int64],
    arm_qpos: NDArray[np.int64],
    act: NDArray[np.int64],
    cols: NDArray[np.int64],
    inv_kp: NDArray[np.float64],
    ctrl_arm: NDArray[np.float64],
    rec: NDArray[np.float64],
    seen: NDArray[np.float64],
    gravity_model: bytes | None,
    rest_q: NDArray[np.float64],
    idx_q: NDArray[np.int64],
    continuous: NDArray[np.uint8],
) -> Stepper: ...
