"""The sensors' rules: on a real link, sampled no faster than physics, seeing something.

Read from the URDF's Gazebo sensor tags (urdf.doc.GazeboSensor: a spec's, as `build`
writes them, or any robot's), so `check` of a foreign URDF catches the same mistakes:

- `sensor-link`: the `<gazebo reference>` names no link (Gazebo drops the sensor);
- `sensor-rate`: an update rate above the physics rate (1 / the spec's control.dt, or
  Gazebo's default 1 ms step): a sensor cannot sample between two steps;
- `sensor-fov`: an empty field of view (several rays between equal angles, a camera's
  horizontal_fov not in (0, pi)); `sensor-range`: range_min >= range_max, near >= far;
- `sensor-sees-robot`: a lidar's rays start inside the robot's own collision shapes, the
  classic mounting mistake (the scan is a ring around the robot). The rays are cast as the
  drive casts them (sim.sensors.raycast) in MuJoCo's model of the URDF at its zero pose,
  each from where it starts (range_min out): one that meets its first surface from inside
  (the surface's outward normal along the ray) started inside that shape.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from armcli.check.context import Context
from armcli.defaults import DEFAULT_DT
from armcli.errors import ArmcliError
from armcli.robot.frames import rpy_quaternion
from armcli.urdf.doc import GazeboSensor

MAX_SELF_RAYS = 4096  # rays of a lidar tried for sensor-sees-robot (evenly spread)


def check(c: Context) -> None:
    """Every rule on every sensor of the URDF."""
    links = {lk.name for lk in c.urdf.links}
    dt = c.opts.spec.control.dt if c.opts.spec is not None else DEFAULT_DT
    seeing = []
    for s in c.urdf.sensors:
        if s.link not in links:
            valid = ", ".join(sorted(links)[:12])
            message = f"sensor {s.name!r} is on {s.link!r}, not a link (links: {valid})"
            c.out.add("sensor-link", s.line, message, sensor=s.name, link=str(s.link))
            continue
        if s.update_rate is not None and s.update_rate * dt > 1.0 + 1e-9:
            c.out.add(
                "sensor-rate",
                s.line,
                f"sensor {s.name!r} updates at {s.update_rate:g} "
                f"Hz, above the physics rate {1.0 / dt:g} Hz (dt = {dt:g} s)",
                sensor=s.name,
                rate=s.update_rate,
                physics_rate=1.0 / dt,
            )
        if not (_fov(c, s) | _range(c, s)) and s.is_lidar:
            seeing.append(s)
    if seeing:
        _sees_robot(c, seeing)


def _fov(c: Context, s: GazeboSensor) -> bool:
    """Report an empty field of view; True when one was reported."""
    for axis, scan in (("horizontal", s.rays), ("vertical", s.vertical)):
        if scan is None or None in scan:
            continue
        n, lo, hi = scan
        assert n is not None and lo is not None and hi is not None
        if n > 1 and hi <= lo:
            c.out.add(
                "sensor-fov",
                s.line,
                f"sensor {s.name!r}: {int(n)} {axis} rays between "
                f"{lo:g} and {hi:g} rad: an empty field of view",
                sensor=s.name,
                min_angle=lo,
                max_angle=hi,
            )
            return True
    fov = s.horizontal_fov
    if fov is not None and not 0.0 < fov < math.pi:
        message = f"sensor {s.name!r}: horizontal_fov {fov:g} rad is not in (0, pi), a pinhole's"
        c.out.add("sensor-fov", s.line, message, sensor=s.name, horizontal_fov=fov)
        return True
    return False


def _range(c: Context, s: GazeboSensor) -> bool:
    """Report a range that ends before it starts; True when one was reported."""
    for (lo, hi), what in ((s.range or (None, None), "range"), (s.clip or (None, None), "clip")):
        if lo is not None and hi is not None and lo >= hi:
            names = ("range_min", "range_max") if what == "range" else ("near", "far")
            c.out.add(
                "sensor-range",
                s.line,
                f"sensor {s.name!r}: {names[0]} {lo:g} m is not below {names[1]} {hi:g} m",
                sensor=s.name,
                **{names[0]: lo, names[1]: hi},
            )
            return True
    return False


def _sees_robot(c: Context, lidars: list[GazeboSensor]) -> None:
    try:
        model, data = _mujoco_model(c, lidars)
    except (ArmcliError, ValueError) as exc:  # MuJoCo cannot take this robot: no verdict
        c.notes.append(f"sensor-sees-robot skipped: no MuJoCo model of the robot ({exc})")
        return
    for s in lidars:
        inside, total, links = _inside(model, data, s)
        if inside:
            c.out.add(
                "sensor-sees-robot",
                s.line,
                f"sensor {s.name!r}: {inside} of its {total} rays start inside the "
                f"collision shape of {', '.join(links)}: the lidar sees its own robot",
                sensor=s.name,
                rays=inside,
            )


def _mujoco_model(c: Context, lidars: list[GazeboSensor]) -> tuple[Any, Any]:
    """MuJoCo's model of the URDF (export mjcf, fixed base) with a site per lidar."""
    import mujoco

    from armcli.export.mjcf import build_mjcf

    ms = mujoco.MjSpec.from_string(build_mjcf(c.urdf).model.decode("utf-8"))
    for s in lidars:
        body = ms.body(s.link) if s.link else None
        if body is None:  # the root `world` link is MuJoCo's worldbody
            body = ms.worldbody
        x, y, z, roll, pitch, yaw = s.pose or (0.0,) * 6
        qx, qy, qz, qw = rpy_quaternion((roll, pitch, yaw))
        body.add_site(name=f"lidar/{s.name}", pos=[x, y, z], quat=[qw, qx, qy, qz])  # MuJoCo's
    model = ms.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return model, data


def _scan(scan: tuple[float | None, ...] | None) -> tuple[float, float, float]:
    """(samples, min, max) with Gazebo's defaults (1 ray at 0) for what is not given."""
    n, lo, hi = scan if scan is not None else (None, None, None)
    return (max(1.0, n or 1.0), lo or 0.0, hi if hi is not None else (lo or 0.0))


def _inside(model: Any, data: Any, s: GazeboSensor) -> tuple[int, int, list[str]]:
    """(rays starting inside a collision shape, rays tried, the links those shapes are on)."""
    import mujoco

    from armcli.sim.sensors.raycast import COLLISION_GROUP
    from armcli.sim.sensors.rays import ray_directions

    dirs = ray_directions(_scan(s.rays), _scan(s.vertical))
    dirs = dirs[np.unique(np.linspace(0, len(dirs) - 1, MAX_SELF_RAYS).astype(int))]
    site = data.site(f"lidar/{s.name}")
    R, origin = site.xmat.reshape(3, 3), site.xpos
    start = (s.range or (0.0, None))[0] or 0.0
    groups = np.zeros(6, dtype=np.uint8)
    groups[COLLISION_GROUP] = 1
    geom, normal = np.zeros(1, dtype=np.int32), np.zeros(3)
    inside, links = 0, set()
    for d in dirs @ R.T:
        hit = mujoco.mj_ray(model, data, origin + start * d, d, groups, 1, -1, geom, normal)
        if hit >= 0.0 and float(normal @ d) > 0.0:
            inside += 1
            links.add(model.body(int(model.geom_bodyid[geom[0]])).name)
    return inside, len(dirs), sorted(links)
