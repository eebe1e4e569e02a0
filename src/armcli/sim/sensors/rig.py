"""Every sensor of a run, each sampled at its own rate while MuJoCo steps.

Sensor j samples at the steps nearest to 0, 1/rate, 2/rate, ... (sim.states' rule for
the output rate), as Gazebo updates a sensor at its `update_rate` in simulated time. The
run loop calls `sample(k, model, data)` after step k's mj_step, when MuJoCo's data holds
the positions, contacts and sensors of state k (its time k dt); `due[k]` says whether any
sensor samples then. A camera without an OpenGL backend samples nothing: one note says
so (sensors.gl). Everything is kept in memory until the run is written, so a run whose
sensors would keep more than MAX_SENSOR_BYTES is refused before it starts.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.errors import InputError
from armcli.sim.sensors import gl
from armcli.sim.sensors.imu import ImuSampler
from armcli.sim.sensors.reading import Reading, Sampler
from armcli.sim.sensors.scanners import DepthSampler, LidarSampler
from armcli.sim.states import sample_steps

if TYPE_CHECKING:  # pydantic models: annotations only
    from armcli.spec.sensors import Sensor

# what a run keeps of its sensors' readings; their MCAP messages take up to 4x more (a depth
# image's point cloud is 3 floats a pixel) until the file is written
MAX_SENSOR_BYTES = 250_000_000


def sample_bytes(sensor: Sensor) -> int:
    """Bytes one sample of `sensor` keeps."""
    if sensor.lidar is not None:
        return 4 * sensor.lidar.samples * sensor.lidar.vertical_samples
    if sensor.camera is not None:
        per_pixel = 4 if sensor.type == "depth_camera" else 3
        return per_pixel * sensor.camera.width * sensor.camera.height
    return 80


@dataclass
class SensorRig:
    """The samplers of a run and when each samples."""

    samplers: list[Sampler]
    due: np.ndarray  # (steps + 1,) bool: some sensor samples at step k
    notes: tuple[str, ...] = ()
    _at: dict[int, list[tuple[Sampler, int]]] = field(default_factory=dict)

    def sample(self, k: int, model: Any, data: Any) -> None:
        """Every sensor due at step k reads MuJoCo's current data."""
        for sampler, j in self._at.get(k, ()):
            sampler.sample(j, model, data)

    def readings(self, dt: float, record: np.ndarray) -> tuple[Reading, ...]:
        """What each sensor recorded, by sensor name; `record`: the run's sensordata rows."""
        return tuple(s.reading(dt, record) for s in self.samplers)


def make_rig(sensors: Mapping[str, Sensor], model: Any, steps: int, dt: float) -> SensorRig:
    """Samplers for `sensors` on the compiled `model` over a run of `steps` steps of `dt`."""
    _refuse_big(sensors, steps, dt)
    samplers: list[Sampler] = []
    notes = []
    for name, s in sorted(sensors.items()):
        k = sample_steps(steps, dt, s.rate)
        if s.type == "camera" and gl.backend() is None:
            notes.append(
                f"camera {name!r} renders nothing: no OpenGL backend for MuJoCo's "
                f"offscreen renderer ({gl.why_none()}); {gl.INSTALL_HINT}"
            )
            continue
        samplers.append(_sampler(name, s, model, k))
    due = np.zeros(steps + 1, dtype=bool)
    at: dict[int, list[tuple[Sampler, int]]] = {}
    for sampler in (s for s in samplers if s.live):
        due[sampler.steps] = True
        for j, k in enumerate(sampler.steps):
            at.setdefault(int(k), []).append((sampler, j))
    return SensorRig(samplers, due, tuple(notes), at)


def _sampler(name: str, s: Sensor, model: Any, steps: np.ndarray) -> Sampler:
    if s.type == "lidar":
        return LidarSampler(name, s, model, steps)
    if s.type == "depth_camera":
        return DepthSampler(name, s, model, steps)
    if s.type == "imu":
        return ImuSampler(name, s, model, steps)
    from armcli.sim.sensors.camera import CameraSampler

    return CameraSampler(name, s, model, steps)


def _refuse_big(sensors: Mapping[str, Sensor], steps: int, dt: float) -> None:
    total = 0
    for name, s in sorted(sensors.items()):
        total += len(sample_steps(steps, dt, s.rate)) * sample_bytes(s)
        if total > MAX_SENSOR_BYTES:
            raise InputError(
                f"the sensors would keep {total / 1e6:.0f} MB over {steps * dt:g} s, more than "
                f"the {MAX_SENSOR_BYTES / 1e6:g} MB a run keeps (sensor {name!r} and those "
                "before it): lower a rate or an image size, or simulate less time",
                field=f"sensors.{name}",
            )
