"""The compiled pinhole caster against MuJoCo's own rays (mj_multiRay), the second engine.

Every primitive MuJoCo has (plane, sphere, capsule, ellipsoid, cylinder, box) at seeded
random poses, seen from outside and from inside a shape, the camera turned every way:
the caster's depth equals mj_multiRay's pixel for pixel, and a mesh's pixels are left to
MuJoCo (the caster marks them), so an image holding a mesh equals mj_multiRay's too.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from armcli.sim.sensors import raycast
from armcli.sim.sensors.rays import R_SENSOR_OPTICAL, Pinhole
from armcli.spec.sensors import Camera

mujoco = pytest.importorskip("mujoco")

AGREE = 1e-9  # [m] both are closed forms in double precision
EDGE_PIXELS = 0  # pixels where the two may disagree (a ray grazing an edge): none seen
CAMERA = Camera(width=48, height=36, horizontal_fov=1.4, near=0.05, far=8.0)
SHAPES = ("sphere", "capsule", "ellipsoid", "cylinder", "box")


def _world(seed: int, mesh: bool = False) -> tuple[Any, Any]:
    rng = np.random.default_rng(seed)
    ms = mujoco.MjSpec()
    ms.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 0.05])
    ms.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[1.0, 0.5, 0.05],
                          pos=[0.0, 0.0, 2.5], quat=[0.0, 1.0, 0.0, 0.0])  # fmt: skip
    for i in range(12):
        kind = SHAPES[i % len(SHAPES)]
        q = rng.normal(size=4)
        ms.worldbody.add_geom(type=getattr(mujoco.mjtGeom, f"mjGEOM_{kind.upper()}"),
                              size=list(rng.uniform(0.1, 0.6, 3)), pos=list(rng.uniform(-3, 3, 3)),
                              quat=list(q / np.linalg.norm(q)))  # fmt: skip
    if mesh:
        ms.add_mesh(name="tetra", uservert=[0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1])
        ms.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="tetra", pos=[1.5, 0, 0.5])
    model = ms.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def _both(model: Any, data: Any, origin: np.ndarray, R_world_sensor: np.ndarray) -> Any:
    mod = raycast.native()
    if mod is None:
        pytest.skip("armcli.sim._raycast is not built (make native)")
    pin = Pinhole.of(CAMERA)
    rays = pin.optical_rays()
    norm = np.linalg.norm(rays, axis=1)
    R = R_world_sensor @ R_SENSOR_OPTICAL
    frame = raycast.PinholeCast(origin, R, pin.fx, pin.fy, pin.cx, pin.cy, pin.width,
                                pin.height, CAMERA.near, CAMERA.far)  # fmt: skip
    fast, other = raycast.cast_pinhole(mod, model, data, raycast.SeenGeoms.of(model), frame)
    slow = raycast.cast(model, data, origin, (rays / norm[:, None]) @ R.T, CAMERA.near * norm,
                        CAMERA.far * norm) / norm  # fmt: skip
    return fast, other, slow


def _differ(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    both = np.isfinite(a) & np.isfinite(b)
    out = np.isfinite(a) != np.isfinite(b)
    out[both] = np.abs(a[both] - b[both]) >= AGREE
    return out


def _rotation(rng: np.random.Generator) -> np.ndarray:
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


@pytest.mark.parametrize("seed", range(6))
def test_the_caster_equals_mj_multiray_on_every_primitive(seed: int) -> None:
    model, data = _world(seed)
    rng = np.random.default_rng(100 + seed)
    seen = 0
    for _ in range(4):
        origin = rng.uniform(-2.5, 2.5, 3)
        origin[2] = abs(origin[2]) + 0.1
        fast, other, slow = _both(model, data, origin, _rotation(rng))
        assert not other.any()
        differ = _differ(fast, slow)
        assert differ.sum() <= EDGE_PIXELS, (seed, origin, fast[differ], slow[differ])
        seen += int(np.isfinite(fast).sum())
    assert seen > 0


def test_from_inside_a_shape_the_caster_sees_its_inside_as_mujoco_does() -> None:
    ms = mujoco.MjSpec()
    ms.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[1.0, 0.8, 0.6], pos=[0.2, 0, 0])
    ms.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.3, 0.4], pos=[0.5, 0, 0])
    model = ms.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    fast, _, slow = _both(model, data, np.zeros(3), np.eye(3))
    assert np.all(np.isfinite(fast))  # inside the box every ray meets a wall
    assert not _differ(fast, slow).any()


def test_a_mesh_is_left_to_mujoco() -> None:
    model, data = _world(0, mesh=True)
    origin, R = np.array([-1.0, 0.0, 0.6]), np.eye(3)  # looking along +x at the tetrahedron
    fast, other, slow = _both(model, data, origin, R)
    assert other.any()
    assert _differ(fast[~other], slow[~other]).sum() <= EDGE_PIXELS  # the primitives: as above


@pytest.mark.parametrize("seed", range(4))
def test_lidar_rays_from_their_start_equal_mujocos(seed: int) -> None:
    if raycast.native() is None:
        pytest.skip("armcli.sim._raycast is not built (make native)")
    model, data = _world(seed, mesh=True)
    rng = np.random.default_rng(200 + seed)
    dirs = rng.normal(size=(500, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    start, stop = rng.uniform(0.0, 1.0, 500), rng.uniform(2.0, 6.0, 500)
    origin = np.array([0.0, 0.0, 0.6])
    fast = raycast.cast(model, data, origin, dirs, start, stop, raycast.SeenGeoms.of(model))
    slow = raycast.cast(model, data, origin, dirs, start, stop)  # mj_multiRay, mj_ray
    assert not _differ(fast, slow).any()
    assert 0 < np.isfinite(fast).sum() < len(fast)
