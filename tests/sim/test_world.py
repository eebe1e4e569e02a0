"""A scene file's objects in the MuJoCo world (sim.world), against closed-form geometry.

The reference for where an object lands is a ray's distance to its surface, computed by
hand from the scene file's numbers (SolidPrimitive's dimensions and the pose), so a wrong
size convention (MuJoCo's half sizes, cylinder [radius, half height] against
SolidPrimitive's [height, radius]) or a wrong pose shows up as a wrong distance.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from armcli.drive import job as drive
from armcli.errors import InputError
from armcli.io.scene import load_scene
from armcli.sim.options import SimOptions
from armcli.sim.world import FLAT_BACK, add_scene, overlaps
from tests.helpers import DEFAULT_SPEC, spec_file

mujoco = pytest.importorskip("mujoco")

RAY_TOL = 1e-9  # [m] MuJoCo's ray-primitive distances are closed forms in double precision
CONE_TOL = 2e-3  # [m] a 64-sided cone's flat sides sit inside the round one by r (1 - cos(pi/64))
CONTACT_TOL = 5e-3  # [m] MuJoCo's soft contact lets the base sink into the wall by mm
S = math.sqrt(0.5)

WORLD = f"""
world:
  collision_objects:
    - id: crate            # a box turned 90 degrees about z: 0.2 x 1.0 becomes 1.0 x 0.2
      pose: {{position: {{x: 2.0}}, orientation: {{z: {S}, w: {S}}}}}
      primitives: [{{type: box, dimensions: [0.2, 1.0, 0.4]}}]
      primitive_poses: [{{position: {{z: 0.2}}}}]
    - id: post             # SolidPrimitive cylinder: [height, radius]
      header: {{frame_id: world}}
      primitives: [{{type: 3, dimensions: [0.8, 0.1]}}]
      primitive_poses: [{{position: {{x: 0.0, y: 1.5, z: 0.4}}}}]
    - id: ball
      primitives: [{{type: sphere, dimensions: [0.25]}}]
      primitive_poses: [{{position: {{x: -1.0, y: 0.0, z: 0.5}}}}]
    - id: cone
      primitives: [{{type: cone, dimensions: [0.6, 0.2]}}]
      primitive_poses: [{{position: {{x: 0.0, y: -2.0, z: 0.3}}}}]
    - id: plate            # a flat mesh square whose vertices sit away from its pose's origin
      meshes:
        - vertices: [{{x: 0, y: -1, z: 0}}, {{x: 0, y: 1, z: 0}}, {{x: 0, y: 1, z: 2}},
                     {{x: 0, y: -1, z: 2}}]
          triangles: [{{vertex_indices: [0, 1, 2]}}, {{vertex_indices: [0, 2, 3]}}]
      mesh_poses: [{{position: {{x: 3.0, y: 5.0, z: 0.0}}}}]
"""


def _scene_model(tmp_path: Path, text: str = WORLD, links: tuple[str, ...] = ()) -> Any:
    path = tmp_path / "world.yaml"
    path.write_text(text)
    ms = mujoco.MjSpec()
    geoms = add_scene(ms, load_scene(path, links))
    model = ms.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data, geoms


def _ray(model: Any, data: Any, start: tuple[float, ...], direction: tuple[float, ...]) -> float:
    geomid = np.zeros(1, dtype=np.int32)
    vec = np.asarray(direction, dtype=float)
    pnt = np.asarray(start, dtype=float)
    return float(mujoco.mj_ray(model, data, pnt, vec / np.linalg.norm(vec), None, 1, -1, geomid))


def test_primitives_land_where_the_scene_file_puts_them(tmp_path: Path) -> None:
    model, data, geoms = _scene_model(tmp_path)
    assert [g.object_id for g in geoms] == ["crate", "post", "ball", "cone", "plate"]
    # crate: turned, it spans x 2 +- 0.5 (its 1.0 side), y +- 0.1, z 0..0.4
    assert _ray(model, data, (0, 0, 0.2), (1, 0, 0)) == pytest.approx(1.5, abs=RAY_TOL)
    assert _ray(model, data, (2.3, -1, 0.2), (0, 1, 0)) == pytest.approx(0.9, abs=RAY_TOL)
    assert _ray(model, data, (2.0, 0, 1.0), (0, 0, -1)) == pytest.approx(0.6, abs=RAY_TOL)
    # post: radius 0.1 about (0, 1.5), top at z = 0.8
    assert _ray(model, data, (0, 0, 0.3), (0, 1, 0)) == pytest.approx(1.4, abs=RAY_TOL)
    assert _ray(model, data, (0, 1.55, 2.0), (0, 0, -1)) == pytest.approx(1.2, abs=RAY_TOL)
    # ball: radius 0.25 about (-1, 0, 0.5)
    assert _ray(model, data, (0, 0, 0.5), (-1, 0, 0)) == pytest.approx(0.75, abs=RAY_TOL)
    # cone: apex at z = 0.6, base radius 0.2 at z = 0: at radius 0.05 its side is at z 0.45
    # (the ray off the mesh's edges: MuJoCo's ray-triangle test may miss an edge exactly);
    # halfway up its radius is 0.1
    down = _ray(model, data, (0.03, -2.04, 1.0), (0, 0, -1))
    assert down == pytest.approx(0.55, abs=CONE_TOL)
    assert _ray(model, data, (0, 0, 0.3), (0, -1, 0)) == pytest.approx(1.9, abs=CONE_TOL)
    # plate: the square's plane is x = 3 (y 4..6, z 0..2 after the pose); its triangles wind
    # counter-clockwise seen from +x, its front; its back face is FLAT_BACK behind it
    assert _ray(model, data, (5, 5, 0.5), (-1, 0, 0)) == pytest.approx(2.0, abs=RAY_TOL)
    assert _ray(model, data, (0, 5, 0.5), (1, 0, 0)) == pytest.approx(3.0 - FLAT_BACK, abs=RAY_TOL)


def test_an_object_on_a_link_rides_on_its_body(tmp_path: Path) -> None:
    ms = mujoco.MjSpec()
    arm = ms.worldbody.add_body(name="hand_link", pos=[0, 0, 1])
    arm.add_joint(type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0])
    arm.add_geom(size=[0.01, 0, 0])
    path = tmp_path / "held.yaml"
    path.write_text("collision_objects:\n  - id: tool\n    header: {frame_id: hand_link}\n"
                    "    primitives: [{type: box, dimensions: [0.1, 0.1, 0.1]}]\n"
                    "    primitive_poses: [{position: {x: 0.5}}]\n")  # fmt: skip
    add_scene(ms, load_scene(path, ["hand_link"]))
    model = ms.compile()
    data = mujoco.MjData(model)
    data.qpos[0] = 0.25  # the hand slides 0.25 m along x: the box with it, to x 0.75 +- 0.05
    mujoco.mj_forward(model, data)
    assert _ray(model, data, (0.3, 0, 1), (1, 0, 0)) == pytest.approx(0.4, abs=RAY_TOL)


def _wall(x_face: float) -> str:
    return (f"collision_objects:\n  - id: wall\n    primitives: [{{type: box, dimensions: "
            f"[0.2, 3.0, 0.6]}}]\n    primitive_poses: [{{position: {{x: {x_face + 0.1}, "
            f"z: 0.3}}}}]\n")  # fmt: skip


def test_driving_into_a_wall_stops_the_base_at_the_wall(tmp_path: Path) -> None:
    (tmp_path / "world.yaml").write_text(_wall(1.0))
    cmd = tmp_path / "cmd.yaml"
    cmd.write_text("commands:\n  - {linear: {x: 0.5}, time_from_start: 0.0}\n")
    opts = SimOptions(duration=3.5)  # 0.5 m/s for 3.5 s would carry it 1.7 m: the wall is at 1
    job = drive.prepare(spec_file(DEFAULT_SPEC), opts, cmd, world=tmp_path / "world.yaml")
    run = drive.run(job)
    x = run.sensors[:, job.model.layout.base_pos][:, 0]
    # the course base_link box is 0.6 m long, centred on base_footprint (the root): its front
    # face is 0.3 m ahead of the root, so the root stops 0.3 m short of the wall's face
    assert x[-1] == pytest.approx(1.0 - 0.3, abs=CONTACT_TOL)
    assert np.max(x) < 1.0 - 0.3 + CONTACT_TOL


def test_an_object_the_robot_stands_in_is_refused(tmp_path: Path) -> None:
    (tmp_path / "world.yaml").write_text(_wall(0.2))  # the base's front face is at x = 0.3
    cmd = tmp_path / "cmd.yaml"
    cmd.write_text("commands:\n  - {linear: {x: 0.0}, time_from_start: 0.0}\n")
    with pytest.raises(InputError, match="object 'wall' overlaps the robot's base_link") as exc:
        drive.prepare(spec_file(DEFAULT_SPEC), SimOptions(duration=0.1), cmd,
                      world=tmp_path / "world.yaml")  # fmt: skip
    assert exc.value.file == str(tmp_path / "world.yaml")


def test_overlaps_ignore_the_floor_and_objects_clear_of_the_robot(tmp_path: Path) -> None:
    model, data, geoms = _scene_model(tmp_path)  # the crate and the cone stand on the floor
    assert list(overlaps(model, data, geoms)) == []


def test_a_mesh_mujoco_cannot_take_is_refused_naming_the_object(tmp_path: Path) -> None:
    text = ("collision_objects:\n  - id: sheet\n    meshes:\n      - vertices: [{x: 0, y: 0, "
            "z: 0}, {x: 1, y: 0, z: 0}, {x: 0, y: 1, z: 0}]\n        triangles: [{vertex_indices: "
            "[0, 1, 2]}]\n    mesh_poses: [{position: {x: 1}}]\n")  # fmt: skip
    with pytest.raises(InputError, match=r"object 'sheet'.*4 vertices") as exc:
        _scene_model(tmp_path, text)
    assert exc.value.file == str(tmp_path / "world.yaml")
