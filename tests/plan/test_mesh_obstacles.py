"""Mesh obstacles in plan scenes: STL, OBJ and PLY files beside the scene, inline triangles.

Issue 42: every mesh obstacle ended in "internal error: ArgumentError:
BVHModelBase.addSubModel(...) did not match C++ signature" (plan.collision._coal_shape
handed NumPy arrays to an overload taking std::vectors). Two independent references: a
point inside or outside the mesh by trimesh's ray test (a box around the tool point
blocks the pose, the same box beside it does not), and coal's primitive box of the same
size, whose verdicts the triangle mesh must repeat over sampled configurations.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.plan.api import PlanOptions, plan_motion
from armcli.plan.ik import tool_pose
from armcli.plan.inputs import Loaded, load_context
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC, run_cli
from tests.meshes import box_triangles, write_stl
from tests.plan.conftest import BOX_SCENE

FORMATS = ("stl", "obj", "ply", "inline")
CUBE = (0.06, 0.06, 0.06)  # [m] around the tool point: the hand link crosses its surface
WALL = (0.04, 0.2, 0.04)  # [m] box_in_the_way.yaml's box
WALL_AT = (0.45, 0.0, 0.85)  # [m] its position
SAMPLES = 150


def _vertices_faces(size: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    tris = box_triangles(size)
    vertices = np.array([v for t in tris for v in t])
    return vertices, np.arange(len(vertices)).reshape(-1, 3)


def _scene(tmp_path: Path, fmt: str, size: tuple[float, float, float], at: np.ndarray) -> Path:
    """A scene with one mesh object `wall` of a box `size` [m] centred `at`, in format `fmt`."""
    import trimesh

    vertices, faces = _vertices_faces(size)
    if fmt == "inline":
        verts = ", ".join(f"{{x: {x!r}, y: {y!r}, z: {z!r}}}" for x, y, z in vertices.tolist())
        tris = ", ".join(f"{{vertex_indices: {list(map(int, f))}}}" for f in faces)
        mesh = f"{{vertices: [{verts}], triangles: [{tris}]}}"
    elif fmt == "stl":
        write_stl(tmp_path / "wall.stl", box_triangles(size))
        mesh = "{path: wall.stl}"
    else:
        trimesh.Trimesh(vertices, faces, process=False).export(tmp_path / f"wall.{fmt}")
        mesh = f"{{path: wall.{fmt}}}"
    x, y, z = (float(v) for v in at)
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "collision_objects:\n  - id: wall\n    header: {frame_id: world}\n"
        f"    meshes: [{mesh}]\n    mesh_poses: [{{position: {{x: {x!r}, y: {y!r}, z: {z!r}}}}}]\n"
    )
    return scene


def _hits_wall(loaded: Loaded, x: np.ndarray) -> bool:
    pair = loaded.context.checker.first_collision(x, every_pair=True)
    return pair is not None and "wall" in pair


@pytest.fixture(scope="module")
def reach_point() -> np.ndarray:
    ctx = load_context(read_robot(DEFAULT_SPEC)).context
    return tool_pose(ctx.robot, ctx.robot.pose("reach"))[0]


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_point_inside_the_mesh_blocks_outside_it_does_not(
    fmt: str, tmp_path: Path, reach_point: np.ndarray
) -> None:
    import trimesh

    cube = trimesh.Trimesh(*_vertices_faces(CUBE), process=False)
    for shift, inside in (((0.0, 0.0, 0.0), True), ((0.0, 0.5, 0.0), False)):
        at = reach_point + np.array(shift)
        assert bool(cube.contains([reach_point - at])[0]) is inside  # trimesh: the reference
        d = tmp_path / f"{fmt}-{inside}"
        d.mkdir()
        loaded = load_context(read_robot(DEFAULT_SPEC), scene=_scene(d, fmt, CUBE, at))
        x = loaded.context.robot.pose("reach")
        assert _hits_wall(loaded, x) is inside
        if not inside:
            assert loaded.context.checker.first_collision(x, every_pair=True) is None


@pytest.mark.parametrize("fmt", FORMATS)
def test_mesh_verdicts_equal_the_primitive_box(fmt: str, tmp_path: Path) -> None:
    mesh = load_context(
        read_robot(DEFAULT_SPEC), scene=_scene(tmp_path, fmt, WALL, np.array(WALL_AT))
    )
    box = load_context(read_robot(DEFAULT_SPEC), scene=BOX_SCENE)
    robot = mesh.context.robot
    xs = np.random.default_rng(7).uniform(robot.lower, robot.upper, (SAMPLES, len(robot.joints)))
    by_mesh = [_hits_wall(mesh, x) for x in xs]
    by_box = []
    for x in xs:
        pair = box.context.checker.first_collision(x, every_pair=True)
        by_box.append(pair is not None and "box" in pair)
    assert by_mesh == by_box
    assert 0 < sum(by_mesh) < SAMPLES  # the sample meets the wall and misses it


def test_plan_goes_around_a_mesh_wall(tmp_path: Path) -> None:
    """The straight home -> reach sweep is blocked by the STL wall; the plan detours."""
    scene = _scene(tmp_path, "stl", WALL, np.array(WALL_AT))
    loaded = load_context(read_robot(DEFAULT_SPEC), scene=scene)
    ctx = loaded.context
    home, reach = ctx.robot.pose("home"), ctx.robot.pose("reach")
    assert not ctx.checker.motion_free(home, reach, 0.02)
    res = plan_motion(ctx, home, reach, PlanOptions(seed=1))
    assert len(res.path) > 2
    assert not any(_hits_wall(loaded, x) for x in res.timed.positions)


def test_plan_with_a_mesh_scene_through_the_cli(tmp_path: Path) -> None:
    """Before: `internal error: ArgumentError: BVHModelBase.addSubModel(...)`, exit 1."""
    scene = _scene(tmp_path, "ply", WALL, np.array(WALL_AT))
    out = tmp_path / "plan.yaml"
    proc = run_cli(["plan", DEFAULT_SPEC, "--to", "reach", "--scene", scene, "-o", out], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert out.is_file() and "internal error" not in proc.stderr
