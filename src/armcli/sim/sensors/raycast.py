"""Casting a sensor's rays into the MuJoCo world: what they hit, and how far away.

Rays see the floor, the world's objects and the robot's collision shapes (geom groups 0, 1
and 3: what Gazebo's ray sensors hit), never the export's visual copies (group 2), and
not the sensor's own body excepted: a lidar mounted inside its link's collision box sees
the box, as in Gazebo (`check` warns). All rays of a sensor leave one point, so
mj_multiRay casts them together; a ray whose first hit lies nearer than where it starts
(a lidar's range_min, a camera's near plane) is cast again from its start with mj_ray.
A distance is +inf where nothing is hit before the ray's end.

The compiled caster (sim/_native/raycast.cpp) does the same for the primitive geoms with
MuJoCo's shapes and the same "first surface at or beyond the start" rule, testing a geom
only on the rays that can meet it: a depth camera's pixels its bounding box covers, a
lidar's rays whose segment passes its bounding sphere; the rays a mesh may meet are cast
by MuJoCo. Without the extension every ray goes through mj_multiRay (the same ranges,
slower).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from armcli.compiled import Extension
from armcli.sim.world import GROUP as WORLD_GROUP

FLOOR_GROUP, COLLISION_GROUP = 0, 3  # the drive's floor; the export's collision geoms
SEEN_GROUPS = np.zeros(6, dtype=np.uint8)
SEEN_GROUPS[[FLOOR_GROUP, WORLD_GROUP, COLLISION_GROUP]] = 1


def cast(
    model: Any,
    data: Any,
    origin: np.ndarray,
    dirs: np.ndarray,
    start: np.ndarray,
    stop: np.ndarray,
    geoms: SeenGeoms | None = None,
) -> np.ndarray:
    """[m] from `origin` along each unit ray of `dirs` (n, 3, world) to its first hit.

    Only hits between `start` and `stop` [m] (per ray) count; +inf where there is none.
    With `geoms` and the compiled caster, the primitives are cast there and only the rays
    that may meet a mesh by MuJoCo.
    """
    mod = native()
    if mod is None or geoms is None:
        return _multiray(model, data, origin, dirs, start, stop)
    n = len(dirs)
    dist, geom, other = np.empty(n), np.empty(n, dtype=np.int32), np.empty(n, dtype=np.uint8)
    mod.cast_rays(
        np.ascontiguousarray(origin, dtype=np.float64),
        np.ascontiguousarray(dirs, dtype=np.float64),
        start,
        stop,
        geoms.types,
        geoms.sizes,
        np.ascontiguousarray(data.geom_xpos[geoms.ids]),
        np.ascontiguousarray(data.geom_xmat[geoms.ids]),
        geoms.aabb,
        geoms.rbound,
        geoms.ids,
        dist,
        geom,
        other,
    )
    for i in np.nonzero(other)[0]:
        dist[i] = _from_start(model, data, origin, dirs[i], start[i], stop[i])
    return dist


def _multiray(
    model: Any, data: Any, origin: np.ndarray, dirs: np.ndarray, start: np.ndarray, stop: np.ndarray
) -> np.ndarray:
    """mj_multiRay from the origin; a ray hitting before its start is cast again from there."""
    import mujoco

    n = len(dirs)
    dist = np.empty(n)
    geom = np.empty(n, dtype=np.int32)
    vec = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1)
    pnt = np.ascontiguousarray(origin, dtype=np.float64)
    mujoco.mj_multiRay(
        model, data, pnt, vec, SEEN_GROUPS, 1, -1, geom, dist, None, n, float(np.max(stop))
    )
    dist[(dist < 0.0) | (dist > stop)] = np.inf
    for i in np.nonzero(dist < start)[0]:  # the ray begins beyond this hit
        dist[i] = _from_start(model, data, pnt, dirs[i], start[i], stop[i])
    return dist


def _from_start(
    model: Any, data: Any, origin: np.ndarray, d: np.ndarray, start: float, stop: float
) -> float:
    """mj_ray of one ray from where it starts: its distance from `origin`, or +inf."""
    import mujoco

    one = np.empty(1, dtype=np.int32)
    hit = mujoco.mj_ray(model, data, origin + start * d, d, SEEN_GROUPS, 1, -1, one)
    return start + hit if 0.0 <= hit <= stop - start else float(np.inf)


# -- the compiled pinhole caster (sim/_native/raycast.cpp) ----------------------------------

SOURCE = Path(__file__).parents[1] / "_native" / "raycast.cpp"
RAYCAST = Extension("armcli.sim._raycast", (SOURCE,), preload=None)
native = RAYCAST.load  # armcli.sim._raycast, or None (not built, stale, or ARMCLI_NO_NATIVE)


@dataclass(frozen=True)
class SeenGeoms:
    """The geoms rays can hit (SEEN_GROUPS, not transparent), as the caster takes them."""

    ids: np.ndarray  # (n,) int32
    types: np.ndarray  # (n,) int32
    sizes: np.ndarray  # (n, 3)
    aabb: np.ndarray  # (n, 6): MuJoCo's bounding box in the geom frame (centre, half sizes)
    rbound: np.ndarray  # (n,): MuJoCo's bounding sphere about the geom frame's origin

    @classmethod
    def of(cls, model: Any) -> SeenGeoms:
        """The model's geoms in SEEN_GROUPS whose alpha is not 0 (mj_ray skips those)."""
        ok = (SEEN_GROUPS[model.geom_group] == 1) & (model.geom_rgba[:, 3] != 0.0)
        ids = np.nonzero(ok)[0].astype(np.int32)
        sizes = np.ascontiguousarray(model.geom_size[ids])
        aabb = np.ascontiguousarray(model.geom_aabb[ids])
        return cls(
            ids, model.geom_type[ids].astype(np.int32), sizes, aabb, model.geom_rbound[ids].copy()
        )


def cast_pinhole(
    mod: ModuleType, model: Any, data: Any, geoms: SeenGeoms, cam: PinholeCast
) -> tuple[np.ndarray, np.ndarray]:
    """(depth [m] per pixel, +inf for none; pixels MuJoCo must cast: meshes) from the caster."""
    n = cam.width * cam.height
    depth, geom, other = np.empty(n), np.empty(n, dtype=np.int32), np.empty(n, dtype=np.uint8)
    mod.cast_pinhole(
        cam.origin,
        cam.R.ravel(),
        cam.fx,
        cam.fy,
        cam.cx,
        cam.cy,
        cam.width,
        cam.height,
        cam.near,
        cam.far,
        geoms.types,
        geoms.sizes,
        np.ascontiguousarray(data.geom_xpos[geoms.ids]),
        np.ascontiguousarray(data.geom_xmat[geoms.ids]),
        geoms.aabb,
        geoms.ids,
        depth,
        geom,
        other,
    )
    return depth, other.astype(bool)


@dataclass(frozen=True)
class PinholeCast:
    """One depth image to cast: the optical frame in the world, the pinhole, the clip planes."""

    origin: np.ndarray  # (3,) [m]
    R: np.ndarray  # (3, 3) R_world_optical
    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int
    near: float
    far: float
