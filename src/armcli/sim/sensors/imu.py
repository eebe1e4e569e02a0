"""An IMU: MuJoCo's gyro, accelerometer and frame orientation at its site, plus noise.

REP 145's conventions, as gazebo_ros_imu_sensor publishes them with
`initial_orientation_as_reference` false: the angular velocity [rad/s] and the linear
acceleration [m/s²] in the sensor's frame, the acceleration a specific force (what an
accelerometer measures: +9.81 up at rest, 0 in free fall), and the orientation of the
sensor frame in the world, which is ENU (x east, y north, z up: the drive's world has z
up, its x along the robot's heading at the start). Gaussian noise per axis from the
spec's `imu`; the orientation is exact.

The rates are means over the sample period (the steps since the previous sample), as a
MEMS IMU's decimation filter reports them: MuJoCo's acceleration of one step chatters
with the soft contacts (±15 m/s² at 1 ms on the course robot driving at 0.5 m/s, while
its 10 ms means stay within the ramp's 2 m/s²), and a sample of one step would alias
that chatter. The drive records every step's `sensordata`, so the means cost nothing
during the run: the sampler reads them afterwards.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.sim.sensors.model import imu_addresses
from armcli.sim.sensors.reading import Reading, gaussian, rng

if TYPE_CHECKING:  # pydantic models: annotations only
    from armcli.spec.sensors import Sensor


class ImuSampler:
    """An IMU's samples: `imu` (samples, 10) quaternion (x, y, z, w), gyro, accelerometer."""

    live = False  # read from the run's record of every step's sensordata afterwards

    def __init__(self, name: str, sensor: Sensor, model: Any, steps: np.ndarray) -> None:
        self.name, self.sensor, self.steps = name, sensor, steps
        self.gyro, self.acc, self.quat = imu_addresses(model, name)
        self.rng = rng(name)

    def sample(self, j: int, model: Any, data: Any) -> None:
        """Nothing during the run (see the module docstring)."""

    def reading(self, dt: float, record: np.ndarray) -> Reading:
        """The samples from `record` (a row of sensordata per state) and their times."""
        k = self.steps
        values = np.empty((len(k), 10))
        w, x, y, z = (record[k, self.quat + i] for i in range(4))
        values[:, :4] = np.column_stack([x, y, z, w])
        values[:, 4:7] = period_mean(record[:, self.gyro : self.gyro + 3], k)
        values[:, 7:10] = period_mean(record[:, self.acc : self.acc + 3], k)
        imu = self.sensor.imu
        if imu is not None:
            values[:, 4:7] += gaussian(self.rng, 0.0, imu.angular_velocity_stddev, (len(k), 3))
            values[:, 7:10] += gaussian(self.rng, 0.0, imu.linear_acceleration_stddev, (len(k), 3))
        return Reading(self.name, self.sensor, k, k * dt, {"imu": values})


def period_mean(x: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Per sample k_j, the mean of rows (k_{j-1}, k_j] (the first sample: row k_0 itself)."""
    c = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0)])
    prev = np.concatenate([[k[0] - 1], k[:-1]])
    out: np.ndarray = (c[k + 1] - c[prev + 1]) / np.maximum(k - prev, 1)[:, None]
    return out


def variances(sensor: Sensor) -> tuple[float, float]:
    """The gyro's and the accelerometer's noise variance per axis (Imu's covariances)."""
    imu = sensor.imu
    if imu is None:
        return 0.0, 0.0
    return imu.angular_velocity_stddev**2, imu.linear_acceleration_stddev**2
