"""The ray sensors: a lidar (one ring or several) and a depth camera.

A lidar's range is the distance from the sensor's origin to the first hit between
range_min and range_max, plus noise, rounded to `resolution`; a ray with nothing in
range reads +inf, REP 117's "no return" (a noisy return is kept within [range_min,
range_max]). A depth camera's pixel is the distance along the optical axis to the first
hit between the near and far planes, plus noise, or +inf with nothing there (REP 118).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.sim.sensors.model import site_name
from armcli.sim.sensors.raycast import PinholeCast, SeenGeoms, cast, cast_pinhole, native
from armcli.sim.sensors.rays import R_SENSOR_OPTICAL, Pinhole, lidar_directions
from armcli.sim.sensors.reading import Reading, gaussian, quantise, rng

if TYPE_CHECKING:  # pydantic models: annotations only
    from armcli.spec.sensors import Sensor


def _pose(data: Any, site: int) -> tuple[np.ndarray, np.ndarray]:
    """(origin, R_world_sensor) of a site in the current state."""
    return data.site_xpos[site], data.site_xmat[site].reshape(3, 3)


class LidarSampler:
    """A lidar's scans: `ranges` (samples, rings, rays per ring) [m], float32."""

    live = True  # samples during the run

    def __init__(self, name: str, sensor: Sensor, model: Any, steps: np.ndarray) -> None:
        assert sensor.lidar is not None
        self.name, self.sensor, self.steps = name, sensor, steps
        li = sensor.lidar
        self.dirs = lidar_directions(li)
        self.site = int(model.site(site_name(name)).id)
        self.start = np.full(len(self.dirs), li.range_min)
        self.stop = np.full(len(self.dirs), li.range_max)
        self.shape = (li.vertical_samples, li.samples)
        self.ranges = np.empty((len(steps), *self.shape), dtype=np.float32)
        self.poses = np.empty((len(steps), 12))  # the sensor in the world: origin, R (rows)
        self.rng = rng(name)
        self.geoms: SeenGeoms | None = SeenGeoms.of(model)  # None: mj_multiRay alone

    def sample(self, j: int, model: Any, data: Any) -> None:
        """Scan once from the site's pose."""
        origin, R = _pose(data, self.site)
        self.poses[j, :3], self.poses[j, 3:] = origin, R.ravel()
        r = cast(model, data, origin, self.dirs @ R.T, self.start, self.stop, self.geoms)
        li, noise = self.sensor.lidar, self.sensor.noise
        assert li is not None
        hit = np.isfinite(r)
        if noise is not None:
            r[hit] = np.clip(
                r[hit] + gaussian(self.rng, noise.mean, noise.stddev, int(hit.sum())),
                li.range_min,
                li.range_max,
            )
        r[hit] = quantise(r[hit], li.resolution)
        self.ranges[j] = r.reshape(self.shape)

    def reading(self, dt: float, record: np.ndarray) -> Reading:
        """The scans and their times."""
        return Reading(
            self.name,
            self.sensor,
            self.steps,
            self.steps * dt,
            {"ranges": self.ranges, "pose": self.poses},
        )


class DepthSampler:
    """A depth camera's images: `depth` (samples, height, width) [m], float32."""

    live = True  # samples during the run

    def __init__(self, name: str, sensor: Sensor, model: Any, steps: np.ndarray) -> None:
        assert sensor.camera is not None
        self.name, self.sensor, self.steps = name, sensor, steps
        cam = sensor.camera
        self.pinhole = Pinhole.of(cam)
        rays = self.pinhole.optical_rays()
        self.norm = np.linalg.norm(rays, axis=1)  # = 1 / the unit ray's optical z
        self.dirs = (rays / self.norm[:, None]) @ R_SENSOR_OPTICAL.T  # unit, sensor frame
        self.start, self.stop = cam.near * self.norm, cam.far * self.norm
        self.site = int(model.site(site_name(name)).id)
        self.depth = np.empty((len(steps), cam.height, cam.width), dtype=np.float32)
        self.rng = rng(name)
        self.native, self.geoms = native(), SeenGeoms.of(model)

    def sample(self, j: int, model: Any, data: Any) -> None:
        """One depth image from the site's pose."""
        origin, R = _pose(data, self.site)
        if self.native is None:
            z = cast(model, data, origin, self.dirs @ R.T, self.start, self.stop) / self.norm
        else:
            z = self._fast(model, data, origin, R)
        noise = self.sensor.noise
        if noise is not None:
            hit = np.isfinite(z)
            z[hit] += gaussian(self.rng, noise.mean, noise.stddev, int(hit.sum()))
        self.depth[j] = z.reshape(self.depth.shape[1:])

    def _fast(self, model: Any, data: Any, origin: np.ndarray, R: np.ndarray) -> np.ndarray:
        """The compiled caster's depths; the pixels a mesh may cover through mj_multiRay."""
        assert self.native is not None and self.sensor.camera is not None
        p, cam = self.pinhole, self.sensor.camera
        frame = PinholeCast(
            origin,
            R @ R_SENSOR_OPTICAL,
            p.fx,
            p.fy,
            p.cx,
            p.cy,
            p.width,
            p.height,
            cam.near,
            cam.far,
        )
        z, other = cast_pinhole(self.native, model, data, self.geoms, frame)
        if other.any():
            dist = cast(
                model,
                data,
                origin,
                self.dirs[other] @ R.T,
                self.start[other],
                self.stop[other],
                self.geoms,
            )
            z[other] = dist / self.norm[other]
        return z

    def reading(self, dt: float, record: np.ndarray) -> Reading:
        """The depth images and their times."""
        return Reading(self.name, self.sensor, self.steps, self.steps * dt, {"depth": self.depth})
