"""Sensors on the arm in a fixed-base run: the run's states replayed in MuJoCo's arm.

The fixed-base engine (Pinocchio) has no rays, so the sensors whose link the simulated
arm carries are sampled afterwards: the run keeps the states at each sensor's sample
steps (and the step before an IMU's), and each is set into MuJoCo's model of the same
URDF (export mjcf, fixed base) standing on a floor at the root's z = 0, among a world's
objects if one is given (seen, not touched: the fixed-base engine has no contacts).
A lidar, depth camera or camera then samples exactly as in a drive (sim.sensors.rig); an
IMU reads MuJoCo's gyro, accelerometer and orientation through inverse dynamics, with
the acceleration of the engine's step into that state ((v_k - v_k-1) / dt): the state's
own, the engine's motion being smooth (no contact chatter to average away).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.io.scene import Scene
from armcli.sim.sensors.model import add_sensors, imu_addresses
from armcli.sim.sensors.reading import Reading, gaussian, rng
from armcli.sim.sensors.rig import make_rig
from armcli.sim.simulate import SimResult
from armcli.sim.states import sample_steps
from armcli.sim.world import add_scene
from armcli.urdf.doc import Urdf

if TYPE_CHECKING:  # pydantic models: annotations only
    from armcli.spec.sensors import Sensor


def arm_sensors(sensors: Mapping[str, Sensor], urdf: Urdf) -> dict[str, Sensor]:
    """The sensors on links of the simulated `urdf` (the arm's), by name."""
    links = {lk.name for lk in urdf.links}
    return {n: s for n, s in sorted(sensors.items()) if s.link in links}


def sensor_steps(sensors: Mapping[str, Sensor], steps: int, dt: float) -> np.ndarray:
    """The steps a run must keep for these sensors (an IMU's also the step before)."""
    out = [np.zeros(0, dtype=np.int64)]
    for s in sensors.values():
        k = sample_steps(steps, dt, s.rate)
        out += [k, np.maximum(k - 1, 0)] if s.type == "imu" else [k]
    return np.concatenate(out)


def arm_readings(
    urdf: Urdf, res: SimResult, sensors: Mapping[str, Sensor], world: Scene | None = None
) -> tuple[tuple[Reading, ...], tuple[str, ...]]:
    """The sensors' readings over the run `res` of `urdf` (its kept states), and notes."""
    import mujoco

    from armcli.export.mjcf import build_mjcf

    ms = mujoco.MjSpec.from_string(build_mjcf(urdf, base="fixed").model.decode("utf-8"))
    ms.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05])
    if world is not None:
        add_scene(ms, world)
    add_sensors(ms, sensors)
    model = ms.compile()
    data = mujoco.MjData(model)
    qpos = np.array([model.jnt_qposadr[model.joint(j).id] for j in res.joint_names], dtype=int)
    dofs = np.array([model.jnt_dofadr[model.joint(j).id] for j in res.joint_names], dtype=int)
    row = {int(k): i for i, k in enumerate(res.step)}
    live = {n: s for n, s in sensors.items() if s.type != "imu"}
    rig = make_rig(live, model, res.steps, res.dt)
    for k in np.nonzero(rig.due)[0]:
        data.qpos[qpos] = res.q[row[int(k)]]
        mujoco.mj_forward(model, data)
        rig.sample(int(k), model, data)
    out = list(rig.readings(res.dt, np.zeros((0, 0))))
    for name, s in sensors.items():
        if s.type == "imu":
            out.append(_imu(name, s, model, data, res, (qpos, dofs), row))
    return tuple(sorted(out, key=lambda r: r.name)), rig.notes


def _imu(
    name: str,
    s: Sensor,
    model: Any,
    data: Any,
    res: SimResult,
    adr: tuple[np.ndarray, np.ndarray],
    row: dict[int, int],
) -> Reading:
    import mujoco

    qpos, dofs = adr
    gyro, acc, quat = imu_addresses(model, name)
    k = sample_steps(res.steps, res.dt, s.rate)
    values = np.empty((len(k), 10))
    for j, step in enumerate(k):
        i, before = row[int(step)], row[max(int(step) - 1, 0)]
        data.qpos[qpos], data.qvel[dofs] = res.q[i], res.v[i]
        data.qacc[:] = 0.0
        data.qacc[dofs] = (res.v[i] - res.v[before]) / res.dt if step > 0 else 0.0
        mujoco.mj_inverse(model, data)
        w, x, y, z = data.sensordata[quat : quat + 4]
        values[j] = (x, y, z, w, *data.sensordata[gyro : gyro + 3], *data.sensordata[acc : acc + 3])
    gen, imu = rng(name), s.imu
    if imu is not None:
        values[:, 4:7] += gaussian(gen, 0.0, imu.angular_velocity_stddev, (len(k), 3))
        values[:, 7:10] += gaussian(gen, 0.0, imu.linear_acceleration_stddev, (len(k), 3))
    return Reading(name, s, k, k * res.dt, {"imu": values})
