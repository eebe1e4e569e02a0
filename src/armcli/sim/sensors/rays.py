"""The rays a lidar or a depth camera casts, in its sensor frame, and the pinhole model.

Gazebo's conventions, so that a scan here and in Gazebo line up: a sensor looks along +x
of its frame (the spec's `origin` on its link), z up. A lidar's ray i of a ring is at
`min_angle + i (max_angle - min_angle) / (samples - 1)` about z, its ring j at
`vertical_min_angle + j (...) / (vertical_samples - 1)`, positive up (Gazebo's
MultiRayShape: direction (cos v cos h, cos v sin h, sin v)). A ray starts `range_min` out
(Gazebo's ray shapes begin there: nothing nearer is seen) and ends at `range_max`.

A camera's image is in the optical frame of REP 103 (z forward, x right, y down: the
`*_optical` frame the course's camera.xacro adds with rpy (-pi/2, 0, -pi/2)), as
gazebo_ros_camera publishes it. The pinhole spans `horizontal_fov` edge to edge over the
image's width with square pixels: fx = fy = (width / 2) / tan(fov / 2), and pixel centres
at integer coordinates, so the principal point is ((width - 1) / 2, (height - 1) / 2).
Pixel (u, v) looks along ((u - cx) / fx, (v - cy) / fy, 1); a depth pixel is the distance
along the optical axis (REP 118), between the `near` and `far` clipping planes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pydantic models: annotations only
    from armcli.spec.sensors import Camera, Lidar

# columns: the optical frame's x, y, z in the sensor frame (x right = -y, y down = -z, z = x)
R_SENSOR_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def spread(lo: float, hi: float, n: int) -> np.ndarray:
    """N angles from lo to hi inclusive (one: lo), as Gazebo spaces a scan's rays."""
    if n == 1:
        return np.array([lo])
    return lo + np.arange(n) * ((hi - lo) / (n - 1))


def lidar_directions(li: Lidar) -> np.ndarray:
    """(rings * samples, 3) unit rays in the sensor frame, ring by ring."""
    vertical = (li.vertical_samples, li.vertical_min_angle, li.vertical_max_angle)
    return ray_directions((li.samples, li.min_angle, li.max_angle), vertical)


def ray_directions(
    horizontal: tuple[float, float, float], vertical: tuple[float, float, float]
) -> np.ndarray:
    """(rings * samples, 3) unit rays of scans given as (samples, min angle, max angle)."""
    h = spread(horizontal[1], horizontal[2], int(horizontal[0]))
    v = spread(vertical[1], vertical[2], int(vertical[0]))
    cv, sv = np.cos(v)[:, None], np.sin(v)[:, None]
    out = np.stack(
        [cv * np.cos(h)[None, :], cv * np.sin(h)[None, :], np.broadcast_to(sv, (len(v), len(h)))],
        axis=-1,
    )
    return np.ascontiguousarray(out.reshape(-1, 3))


def angle_increment(li: Lidar) -> float:
    """[rad] between two rays of a ring (LaserScan's angle_increment; 0 for one ray)."""
    return (li.max_angle - li.min_angle) / (li.samples - 1) if li.samples > 1 else 0.0


@dataclass(frozen=True)
class Pinhole:
    """A camera's image: size [px], focal lengths and principal point [px]."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def of(cls, cam: Camera) -> Pinhole:
        """The pinhole of a spec camera (see the module docstring)."""
        f = (cam.width / 2.0) / math.tan(cam.horizontal_fov / 2.0)
        return cls(cam.width, cam.height, f, f, (cam.width - 1) / 2.0, (cam.height - 1) / 2.0)

    @property
    def K(self) -> np.ndarray:
        """The 3x3 intrinsic matrix (CameraInfo's k)."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def vertical_fov(self) -> float:
        """[rad] the field of view across the image's height."""
        return 2.0 * math.atan((self.height / 2.0) / self.fy)

    def optical_rays(self) -> np.ndarray:
        """(height * width, 3) rays (x_n, y_n, 1) per pixel, row by row, not normalised."""
        u = (np.arange(self.width) - self.cx) / self.fx
        v = (np.arange(self.height) - self.cy) / self.fy
        uu, vv = np.meshgrid(u, v)
        return np.stack([uu.ravel(), vv.ravel(), np.ones(uu.size)], axis=-1)
