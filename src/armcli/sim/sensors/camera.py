"""A camera sensor's images: MuJoCo's offscreen renderer from the sensor's MuJoCo camera.

The scene is what a person sees: the floor, the world's objects and the robot's visual
geoms (groups 0, 1, 2; not the collision copies of group 3 nor the sites), lit by the
model's lights and MuJoCo's headlight. Noise is added to each channel as Gazebo does,
on intensities in [0, 1]; the pixel format follows the spec's (`rgb8`, `bgr8`, `mono8`).
The GL context is the one `gl` found (EGL or OSMesa); without one there is no sampler.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.sim.sensors import gl
from armcli.sim.sensors.model import site_name
from armcli.sim.sensors.reading import Reading, gaussian, rng

if TYPE_CHECKING:  # pydantic models: annotations only
    from armcli.spec.sensors import Sensor

ENCODINGS = {"R8G8B8": "rgb8", "RGB_INT8": "rgb8", "B8G8R8": "bgr8", "L8": "mono8"}
LUMA = np.array([0.299, 0.587, 0.114])  # ITU-R BT.601, for a mono camera
SHOWN_GROUPS = (0, 1, 2)  # floor, world objects, visual geoms
MAX_GEOMS = 10_000


def encoding(sensor: Sensor) -> str:
    """The sensor_msgs/Image encoding of the camera's pixel format."""
    assert sensor.camera is not None
    return ENCODINGS[sensor.camera.format]


class CameraSampler:
    """A camera's images: `image` (samples, height, width, channels) uint8."""

    live = True  # samples during the run

    def __init__(self, name: str, sensor: Sensor, model: Any, steps: np.ndarray) -> None:
        import mujoco

        assert sensor.camera is not None
        self.name, self.sensor, self.steps = name, sensor, steps
        w, h = sensor.camera.width, sensor.camera.height
        self.ctx = gl.context(w, h)
        self.mjr = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.mjr)
        self.scene = mujoco.MjvScene(model, maxgeom=MAX_GEOMS)
        self.cam = mujoco.MjvCamera()
        self.cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self.cam.fixedcamid = int(model.camera(site_name(name)).id)
        self.opt = mujoco.MjvOption()
        self.opt.geomgroup[:] = [int(g in SHOWN_GROUPS) for g in range(len(self.opt.geomgroup))]
        self.opt.sitegroup[:] = 0
        self.rect = mujoco.MjrRect(0, 0, w, h)
        self.rgb = np.empty((h, w, 3), dtype=np.uint8)
        channels = 1 if encoding(sensor) == "mono8" else 3
        self.image = np.empty((len(steps), h, w, channels), dtype=np.uint8)
        self.rng = rng(name)

    def sample(self, j: int, model: Any, data: Any) -> None:
        """Render one image from the camera's pose."""
        import mujoco

        self.ctx.make_current()
        mujoco.mjv_updateScene(
            model, data, self.opt, None, self.cam, mujoco.mjtCatBit.mjCAT_ALL, self.scene
        )
        mujoco.mjr_render(self.rect, self.scene, self.mjr)
        mujoco.mjr_readPixels(self.rgb, None, self.rect, self.mjr)
        img = self.rgb[::-1].astype(np.float64) / 255.0  # OpenGL's rows start at the bottom
        noise = self.sensor.noise
        if noise is not None:
            img = np.clip(img + gaussian(self.rng, noise.mean, noise.stddev, img.shape), 0, 1)
        kind = encoding(self.sensor)
        if kind == "mono8":
            img = (img @ LUMA)[..., None]
        elif kind == "bgr8":
            img = img[..., ::-1]
        self.image[j] = np.round(img * 255.0).astype(np.uint8)

    def reading(self, dt: float, record: np.ndarray) -> Reading:
        """The images and their times (the GL context is released)."""
        self.close()
        return Reading(self.name, self.sensor, self.steps, self.steps * dt, {"image": self.image})

    def close(self) -> None:
        """Free the GL resources (safe to call twice)."""
        if self.ctx is not None:
            self.ctx.make_current()
            self.mjr.free()
            self.ctx.free()
            self.ctx = None
