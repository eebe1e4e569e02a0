"""Types of the compiled pinhole caster `armcli.sim._raycast` (bindings in _native/raycast.cpp).

Keep it in step with the `NB_MODULE` block at the end of raycast.cpp.
"""

import numpy as np
from numpy.typing import NDArray

SOURCE_SHA256: str

def cast_pinhole(
    origin: NDArray[np.float64],
    R: NDArray[np.float64],
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    width: int,
    height: int,
    near: float,
    far: float,
    types: NDArray[np.int32],
    sizes: NDArray[np.float64],
    pos: NDArray[np.float64],
    mats: NDArray[np.float64],
    aabb: NDArray[np.float64],
    ids: NDArray[np.int32],
    depth: NDArray[np.float64],
    geom: NDArray[np.int32],
    other: NDArray[np.uint8],
) -> None:
    """Cast a pinhole's rays against primitive geoms, in place (see raycast.cpp)."""

def cast_rays(
    origin: NDArray[np.float64],
    dirs: NDArray[np.float64],
    start: NDArray[np.float64],
    stop: NDArray[np.float64],
    types: NDArray[np.int32],
    sizes: NDArray[np.float64],
    pos: NDArray[np.float64],
    mats: NDArray[np.float64],
    aabb: NDArray[np.float64],
    rbound: NDArray[np.float64],
    ids: NDArray[np.int32],
    dist: NDArray[np.float64],
    geom: NDArray[np.int32],
    other: NDArray[np.uint8],
) -> None:
    """Cast rays from one point against primitive geoms, in place (see raycast.cpp)."""
