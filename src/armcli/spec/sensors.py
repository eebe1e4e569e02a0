"""Sensors on links: camera, depth camera, 2-D/3-D lidar and IMU.

One description per sensor (where, how often, what it sees, how noisy, which topic),
compiled for Gazebo classic (gazebo_ros sensor plugins, in `build`'s URDF) and for
Gazebo Harmonic (gz-sim sensors and the ros_gz_bridge configuration of the
`--target jazzy` bringup), and simulated by `simulate` (sim.sensors) from the same
fields: one source for the tags and the data.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from armcli.spec.shapes import Origin
from armcli.spec.types import NonNeg, Positive, Real, UrdfName, _Model

Count = Annotated[int, Field(ge=1, le=100_000)]
Topic = Annotated[
    str, Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*$", max_length=128)
]
SensorType = Literal["camera", "depth_camera", "lidar", "imu"]


class Noise(_Model):
    """Gaussian noise added to each measurement."""

    mean: Real = Field(0.0, description="mean [SI unit of the measurement]")
    stddev: NonNeg = Field(description="standard deviation [SI unit of the measurement]")


class Camera(_Model):
    """Image size, field of view and clipping range of a camera or depth camera."""

    width: Count = Field(description="image width [pixels]")
    height: Count = Field(description="image height [pixels]")
    horizontal_fov: Positive = Field(description="horizontal field of view [rad]")
    near: Positive = Field(0.02, description="near clipping distance [m]")
    far: Positive = Field(100.0, description="far clipping distance [m]")
    format: Literal["R8G8B8", "L8", "B8G8R8", "RGB_INT8"] = Field(
        "R8G8B8", description="pixel format"
    )

    @model_validator(mode="after")
    def _range(self) -> Camera:
        if self.far <= self.near:
            raise ValueError("far must be beyond near")
        return self


class Lidar(_Model):
    """A scanning rangefinder: one ring (2-D) or several (3-D, `vertical_samples` > 1)."""

    samples: Count = Field(description="rays per revolution (horizontal) [-]")
    min_angle: Real = Field(description="first ray, about z [rad]")
    max_angle: Real = Field(description="last ray, about z [rad]")
    vertical_samples: Count = Field(1, description="rings; 1 is a 2-D lidar [-]")
    vertical_min_angle: Real = Field(0.0, description="lowest ring, about y [rad]")
    vertical_max_angle: Real = Field(0.0, description="highest ring, about y [rad]")
    range_min: Positive = Field(description="shortest range [m]")
    range_max: Positive = Field(description="longest range [m]")
    resolution: Positive = Field(0.01, description="range resolution [m]")

    @model_validator(mode="after")
    def _ranges(self) -> Lidar:
        if self.max_angle < self.min_angle or self.vertical_max_angle < self.vertical_min_angle:
            raise ValueError("max_angle must be >= min_angle")
        if self.range_max <= self.range_min:
            raise ValueError("range_max must be beyond range_min")
        return self

    @property
    def is_3d(self) -> bool:
        """Whether it has several rings (a point cloud rather than a scan)."""
        return self.vertical_samples > 1


class Imu(_Model):
    """Noise of an IMU's gyroscopes and accelerometers (per axis)."""

    angular_velocity_stddev: NonNeg = Field(0.0, description="gyro noise [rad/s]")
    linear_acceleration_stddev: NonNeg = Field(0.0, description="accelerometer noise [m/s²]")


class Sensor(_Model):
    """A sensor fixed on `link` at `origin`, publishing on `topic` at `rate`."""

    type: SensorType = Field(description="camera, depth_camera, lidar or imu")
    link: UrdfName = Field(description="link the sensor is fixed to")
    origin: Origin = Field(Origin(), description="pose of the sensor in the link frame")
    rate: Positive = Field(description="update rate [Hz]")
    topic: Topic = Field(description="ROS topic (base name for cameras: TOPIC/image_raw, ...)")
    frame: UrdfName | None = Field(
        None, description="frame_id of the messages (e.g. an optical frame); default the link"
    )
    camera: Camera | None = Field(None, description="camera and depth_camera: the image")
    lidar: Lidar | None = Field(None, description="lidar: the rays and ranges")
    imu: Imu | None = Field(None, description="imu: the noise")
    noise: Noise | None = Field(None, description="camera, lidar: Gaussian noise")
    visualize: bool = Field(False, description="draw the sensor in Gazebo's GUI")

    @model_validator(mode="after")
    def _kind(self) -> Sensor:
        need = {"camera": "camera", "depth_camera": "camera", "lidar": "lidar", "imu": None}
        for part in ("camera", "lidar", "imu"):
            given = getattr(self, part) is not None
            wanted = need[self.type] == part or (part == "imu" and self.type == "imu")
            if need[self.type] == part and not given:
                raise ValueError(f"a {self.type} needs `{part}`")
            if given and not wanted:
                raise ValueError(f"`{part}` is for another sensor type than {self.type}")
        if self.noise is not None and self.type == "imu":
            raise ValueError("an imu's noise is given in `imu`")
        return self

    @property
    def frame_id(self) -> str:
        """The frame the messages are stamped in."""
        return self.frame or self.link
