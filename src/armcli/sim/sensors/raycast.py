"""Casting a sensor's rays into the MuJoCo world: what they hit, and how far away.

Rays see the floor, the world's objects and the robot's collision shapes (geom groups 0, 1
and 3: what Gazebo's ray sensors hit), never the export's visual copies (group 2), and
not the sensor's own body excepted: a lidar mounted inside its link's collision box sees
the box, as in Gazebo (`check` warns). All rays of a sensor leave one point, so
mj_multiRay casts them together; a ray whose first hit lies nearer than where it starts
(a lidar's range_min, a camera's near plane) is cast again from its start with mj_ray.
A distance is +inf where nothing is hit before the ray's end.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from armcli.sim.world import GROUP as WORLD_GROUP

FLOOR_GROUP, COLLISION_GROUP = 0, 3  # the drive's floor; the export's collision geoms
SEEN_GROUPS = np.zeros(6, dtype=np.uint8)
SEEN_GROUPS[[FLOOR_GROUP, WORLD_GROUP, COLLISION_GROUP]] = 1


def cast(
    model: Any, data: Any, origin: np.ndarray, dirs: np.ndarray, start: np.ndarray, stop: np.ndarray
) -> np.ndarray:
    """[m] from `origin` along each unit ray of `dirs` (n, 3, world) to its first hit.

    Only hits between `start` and `stop` [m] (per ray) count; +inf where there is none.
    """
    import mujoco

    n = len(dirs)
    dist = np.empty(n)
    geom = np.empty(n, dtype=np.int32)
    vec = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1)
    pnt = np.ascontiguousarray(origin, dtype=np.float64)
    mujoco.mj_multiRay(model, data, pnt, vec, SEEN_GROUPS, 1, -1, geom, dist, None, n,
                       float(np.max(stop)))  # fmt: skip
    early = np.nonzero((dist >= 0.0) & (dist < start))[0]
    one = np.empty(1, dtype=np.int32)
    for i in early:  # the ray begins beyond this hit: cast it again from where it starts
        again = mujoco.mj_ray(model, data, pnt + start[i] * dirs[i], dirs[i], SEEN_GROUPS, 1, -1,
                              one)  # fmt: skip
        dist[i] = start[i] + again if again >= 0.0 else -1.0
    dist[(dist < 0.0) | (dist > stop)] = np.inf
    return dist
