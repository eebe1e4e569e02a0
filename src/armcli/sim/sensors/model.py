"""The spec's sensors in the MuJoCo model: a site per sensor, MuJoCo's IMU sensors, cameras.

Added to the model editor (MjSpec) before it compiles, on the body of the sensor's link
(the export names bodies after links), at the sensor's `origin`:

- a site `sensor/NAME`: where rays start and how they turn with the link;
- an IMU: MuJoCo's gyro, accelerometer and framequat sensors on that site, appended to
  `sensordata` after the drive's own (its Layout is untouched): the rate of turn and the
  specific force in the site's frame (+g up at rest), the site's orientation in the world;
- a camera: a MuJoCo camera `sensor/NAME` looking along the site's +x (MuJoCo's cameras
  look along their -z, y up), its vertical field of view from the pinhole, and an
  offscreen buffer large enough for the image.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.errors import InputError
from armcli.sim.sensors.rays import Pinhole

if TYPE_CHECKING:  # the pydantic models: not loaded by a run that reads no spec
    from armcli.spec.sensors import Sensor

PREFIX = "sensor/"
IMU_PARTS = ("gyro", "accelerometer", "framequat")  # in sensordata order: 3, 3, 4 numbers
SITE_GROUP = 5  # hidden in MuJoCo's viewer by default, as the drive's touch sites
# columns: a MuJoCo camera's x (right), y (up), z (backward) in the sensor frame
R_SENSOR_MJCAMERA = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def quat(rpy: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """(w, x, y, z) of URDF's roll-pitch-yaw about fixed axes (R = Rz Ry Rx), as MuJoCo's."""
    import mujoco

    q = np.zeros(4)
    mujoco.mju_euler2Quat(q, np.asarray(rpy, dtype=float), "XYZ")
    w, x, y, z = (float(v) for v in q)
    return w, x, y, z


def site_name(sensor: str) -> str:
    """The site (and camera) of sensor `sensor`."""
    return f"{PREFIX}{sensor}"


def imu_name(sensor: str, part: str) -> str:
    """The MuJoCo sensor holding one part of an IMU's reading."""
    return f"{PREFIX}{sensor}/{part}"


def add_sensors(ms: Any, sensors: Mapping[str, Sensor]) -> None:
    """Add each sensor's site (and IMU sensors, camera) to the MjSpec `ms`."""
    import mujoco

    for name, s in sorted(sensors.items()):
        body = ms.body(s.link)
        if body is None:  # spec semantics checked the link; a world link has no body here
            raise InputError(
                f"sensor {name!r}: link {s.link!r} has no body in the model",
                field=f"sensors.{name}.link",
            )
        q = quat(s.origin.rpy)
        body.add_site(name=site_name(name), pos=list(s.origin.xyz), quat=list(q), group=SITE_GROUP)
        if s.type == "imu":
            S, obj = mujoco.mjtSensor, mujoco.mjtObj.mjOBJ_SITE
            kinds = (S.mjSENS_GYRO, S.mjSENS_ACCELEROMETER, S.mjSENS_FRAMEQUAT)
            for part, kind in zip(IMU_PARTS, kinds, strict=True):
                ms.add_sensor(
                    name=imu_name(name, part), type=kind, objtype=obj, objname=site_name(name)
                )
        elif s.type == "camera" and s.camera is not None:
            _camera(ms, body, name, s)


def _camera(ms: Any, body: Any, name: str, s: Sensor) -> None:
    assert s.camera is not None
    pin = Pinhole.of(s.camera)
    R_link_sensor = _matrix(quat(s.origin.rpy))
    q = np.zeros(4)
    import mujoco

    mujoco.mju_mat2Quat(q, (R_link_sensor @ R_SENSOR_MJCAMERA).ravel())
    body.add_camera(
        name=site_name(name),
        pos=list(s.origin.xyz),
        quat=list(q),
        fovy=float(np.degrees(pin.vertical_fov)),
    )
    glob = ms.visual.global_
    glob.offwidth = max(int(glob.offwidth), pin.width)
    glob.offheight = max(int(glob.offheight), pin.height)
    ms.visual.map.znear = min(float(ms.visual.map.znear), 1e-3)  # x the model's extent


def _matrix(q: tuple[float, float, float, float]) -> np.ndarray:
    import mujoco

    out = np.zeros(9)
    mujoco.mju_quat2Mat(out, np.asarray(q, dtype=float))
    return out.reshape(3, 3)


def imu_addresses(model: Any, sensor: str) -> tuple[int, int, int]:
    """Where the gyro, accelerometer and framequat of IMU `sensor` start in sensordata."""
    a, b, c = (int(model.sensor(imu_name(sensor, p)).adr[0]) for p in IMU_PARTS)
    return a, b, c
