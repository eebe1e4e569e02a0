"""A sensor on a body in a world of scene-file objects, compiled by MuJoCo: the tests' stage.

The sensor sits on a body `mount` placed at `mount_pos` with yaw `mount_yaw` in a model
holding only the floor and the scene's objects, so every distance it measures follows in
closed form from the scene file's numbers and these poses.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from armcli.io.scene import load_scene
from armcli.sim.sensors.model import add_sensors
from armcli.sim.world import add_scene
from armcli.spec.sensors import Sensor

MOUNT = "mount"


def sensor(**fields: Any) -> Sensor:
    """A spec sensor on the mount body."""
    return Sensor.model_validate({"link": MOUNT, "rate": 10, "topic": "s", **fields})


def stage(
    tmp_path: Path,
    scene_yaml: str,
    sensors: dict[str, Sensor],
    mount_pos: tuple[float, float, float] = (0.0, 0.0, 0.0),
    mount_yaw: float = 0.0,
) -> tuple[Any, Any]:
    """(model, data) after mj_forward: floor, the scene's objects, the sensors on the mount."""
    import mujoco

    path = tmp_path / "world.yaml"
    path.write_text(scene_yaml)
    ms = mujoco.MjSpec()
    ms.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 0.05])
    c, s = math.cos(mount_yaw / 2), math.sin(mount_yaw / 2)
    ms.worldbody.add_body(name=MOUNT, pos=list(mount_pos), quat=[c, 0.0, 0.0, s])
    add_scene(ms, load_scene(path, []))
    add_sensors(ms, sensors)
    model = ms.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def boxes_and_cylinders(
    boxes: Sequence[Sequence[float]], cylinders: Sequence[Sequence[float]]
) -> str:
    """A scene of axis-aligned boxes (x, y, z, sx, sy, sz), upright cylinders (x, y, z, h, r)."""
    lines = ["collision_objects:"]
    for kind, items in (("box", boxes), ("cylinder", cylinders)):
        for i, (x, y, z, *dims) in enumerate(items):
            pose = f"{{position: {{x: {x}, y: {y}, z: {z}}}}}"
            lines += [f"  - id: {kind}{i}",
                      f"    primitives: [{{type: {kind}, dimensions: {list(dims)}}}]",
                      f"    primitive_poses: [{pose}]"]  # fmt: skip
    return "\n".join(lines) + "\n"


def ray_box(o: np.ndarray, d: np.ndarray, centre: np.ndarray, half: np.ndarray) -> float:
    """Closed form (slabs): distance along unit `d` from `o` to an axis-aligned box, or inf."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (centre - half - o) / d, (centre + half - o) / d
    lo, hi = np.nanmax(np.minimum(t1, t2)), np.nanmin(np.maximum(t1, t2))
    if hi < max(lo, 0.0):
        return math.inf
    return float(lo if lo >= 0.0 else hi)


def ray_cylinder(o: np.ndarray, d: np.ndarray, centre: np.ndarray, h: float, r: float) -> float:
    """Closed form: distance along unit `d` from `o` outside an upright cylinder to it, or inf."""
    p = o - centre
    a = d[0] ** 2 + d[1] ** 2
    b = p[0] * d[0] + p[1] * d[1]
    c = p[0] ** 2 + p[1] ** 2 - r * r
    best = math.inf
    if a > 0 and b * b - a * c >= 0:
        t = (-b - math.sqrt(b * b - a * c)) / a
        if t >= 0 and abs(p[2] + t * d[2]) <= h / 2:
            best = t
    for z in (-h / 2, h / 2):
        if d[2] != 0:
            t = (z - p[2]) / d[2]
            if 0 <= t < best and (p[0] + t * d[0]) ** 2 + (p[1] + t * d[1]) ** 2 <= r * r:
                best = t
    return best
