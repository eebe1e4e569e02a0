"""What a sensor recorded over a run, and the noise and rounding every sampler shares.

Noise is Gaussian with the spec's mean and standard deviation, drawn from a generator
seeded by the sensor's name: the same run gives the same readings, and two sensors
never share a stream. A sensor without `noise` (an IMU with zero deviations) reads
exactly.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

if TYPE_CHECKING:  # pydantic models: annotations only
    from armcli.spec.sensors import Sensor


@dataclass(frozen=True)
class Reading:
    """One sensor's samples: at `steps` (times `time` [s]), arrays by kind in `data`.

    lidar: `ranges` (n, rings, samples) [m] and `pose` (n, 12): the sensor's origin [m] and
    rotation (rows) in the world when it scanned; depth_camera: `depth` (n, h, w) [m];
    camera: `image` (n, h, w, channels) uint8; imu: `imu` (n, 10): quaternion (x, y, z, w),
    angular velocity [rad/s], linear acceleration [m/s²], in the sensor frame.
    """

    name: str
    sensor: Sensor
    steps: np.ndarray
    time: np.ndarray
    data: dict[str, np.ndarray] = field(default_factory=dict)


class Sampler(Protocol):
    """One sensor during a run: sample j (of its schedule) from MuJoCo's data."""

    name: str
    sensor: Sensor
    steps: np.ndarray
    live: bool  # samples during the run (False: from the run's record afterwards)

    def sample(self, j: int, model: Any, data: Any) -> None:
        """Read sample j from the model's current state."""
        ...

    def reading(self, dt: float, record: np.ndarray) -> Reading:
        """Everything sampled, at time step `dt` [s]; `record`: sensordata per state."""
        ...


def rng(name: str) -> np.random.Generator:
    """The noise stream of sensor `name`: seeded by the name, so runs repeat."""
    return np.random.default_rng(zlib.crc32(name.encode("utf-8")))


def gaussian(gen: np.random.Generator, mean: float, stddev: float, shape: Any) -> Any:
    """Noise to add, or 0.0 when there is none (the generator is then not drawn from)."""
    if stddev == 0.0 and mean == 0.0:
        return 0.0
    return gen.normal(mean, stddev, shape) if stddev > 0.0 else mean


def quantise(x: np.ndarray, step: float) -> np.ndarray:
    """`x` rounded to multiples of `step` (a range's resolution); inf stays inf."""
    out: np.ndarray = np.round(x / step) * step
    return out
