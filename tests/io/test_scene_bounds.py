"""A scene is bounded before it costs anything, and reads no file its meshes name (issue 42).

Before: 40 objects naming one 19.9 MB PLY (each under the per-mesh caps) reached 2.8 GB in
`plan`; ~8,700 small boxes did not finish in 90 s; an OBJ whose `mtllib` or a glTF whose
buffer was a FIFO in the scene directory hung the reader; a mesh scale of 1e308 overflowed
to inf with NumPy warnings (errors under pytest) or an internal error later.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from armcli.errors import SpecError
from armcli.io.scene import MAX_SCENE_SHAPES, MAX_SCENE_TRIANGLES, load_scene
from tests.helpers import DEFAULT_SPEC, run_cli
from tests.meshes import box_triangles, write_stl

LINKS = ["base_link"]
HANG_S = 20  # a FIFO blocks forever; reading a small mesh takes milliseconds


@pytest.fixture
def no_hang() -> Iterator[list[int]]:
    """Interrupt a blocked open of a FIFO (SIGALRM); the list says whether it had to.

    trimesh catches the interruption while reading a material library and goes on, so a
    test asserts the list is empty instead of relying on the exception.
    """
    fired: list[int] = []

    def timeout(signum: int, _frame: object) -> None:
        fired.append(signum)
        raise TimeoutError(f"the scene reader blocked for {HANG_S} s")

    old = signal.signal(signal.SIGALRM, timeout)
    signal.alarm(HANG_S)
    try:
        yield fired
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _mesh_objects(name: str, count: int, scale: str = "[1, 1, 1]") -> str:
    one = (
        "  - id: m{k}\n    meshes: [{{path: " + name + ", scale: " + scale + "}}]\n"
        "    mesh_poses: [{{position: {{x: 2.0}}}}]\n"
    )
    return "collision_objects:\n" + "".join(one.format(k=k) for k in range(count))


def _problem(path: Path) -> tuple[str, str]:
    with pytest.raises(SpecError) as info:
        load_scene(path, LINKS)
    assert len(info.value.problems) == 1, info.value.lines()
    first = info.value.problems[0]
    return first.field, first.message


def test_an_obj_material_library_that_is_a_fifo_is_not_opened(
    tmp_path: Path, no_hang: list[int]
) -> None:
    import os

    os.mkfifo(tmp_path / "wall.mtl")
    (tmp_path / "wall.obj").write_text(
        "mtllib wall.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl a\n"
        "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
    )
    scene = tmp_path / "scene.yaml"
    scene.write_text(_mesh_objects("wall.obj", 1))
    (obj,) = load_scene(scene, LINKS).objects
    assert no_hang == []  # before: blocked opening wall.mtl until SIGALRM
    triangles = obj.shapes[0].triangles
    assert triangles is not None and len(triangles) == 4


@pytest.mark.parametrize("buffer", ["fifo", "file"])
def test_a_gltf_with_buffers_in_other_files_is_refused(
    buffer: str, tmp_path: Path, no_hang: list[int]
) -> None:
    import os

    import trimesh

    files = trimesh.exchange.gltf.export_gltf(trimesh.creation.box())  # + gltf_buffer_*.bin
    for name, data in files.items():
        (tmp_path / ("wall.gltf" if name == "model.gltf" else name)).write_bytes(data)
    if buffer == "fifo":
        for name in tmp_path.glob("*.bin"):
            name.unlink()
            os.mkfifo(name)
    scene = tmp_path / "scene.yaml"
    scene.write_text(_mesh_objects("wall.gltf", 1))
    field, message = _problem(scene)
    assert no_hang == []
    assert field == "collision_objects[0].meshes[0].path"
    assert "a glTF whose data is in other files ('gltf_buffer_0.bin') is not read" in message


def test_a_glb_holds_its_own_data(tmp_path: Path) -> None:
    import trimesh

    trimesh.creation.box().export(tmp_path / "wall.glb")
    scene = tmp_path / "scene.yaml"
    scene.write_text(_mesh_objects("wall.glb", 1))
    (obj,) = load_scene(scene, LINKS).objects
    assert obj.shapes[0].triangles is not None and len(obj.shapes[0].triangles) == 12


def test_one_mesh_named_by_many_objects_is_bounded_in_total(tmp_path: Path) -> None:
    per_file = MAX_SCENE_TRIANGLES // 39 + 1  # 39 copies pass the budget; each is under the caps
    faces = np.arange(3 * per_file).reshape(-1, 3)
    vertices = np.random.default_rng(0).uniform(-0.1, 0.1, (3 * per_file, 3))
    import trimesh

    trimesh.Trimesh(vertices, faces, process=False).export(tmp_path / "big.ply")
    scene = tmp_path / "scene.yaml"
    scene.write_text(_mesh_objects("big.ply", 40))
    field, message = _problem(scene)
    assert field == "collision_objects[38].meshes[0].path"  # the 39th copy, before it is parsed
    assert f"'big.ply' declares {per_file} triangles" in message
    assert f"of the scene's {MAX_SCENE_TRIANGLES}-triangle bound" in message


def test_too_many_objects_are_refused_before_any_is_read(tmp_path: Path) -> None:
    box = "- {{id: b{k}, primitives: [{{type: 1, dimensions: [.01, .01, .01]}}],"
    box += " primitive_poses: [{{}}]}}\n"  # flow style: 8,700 of them fit the 1 MB YAML cap
    scene = tmp_path / "scene.yaml"
    scene.write_text("collision_objects:\n" + "".join(box.format(k=k) for k in range(8700)))
    field, message = _problem(scene)
    assert field == "collision_objects"
    assert f"8700 collision objects, more than the {MAX_SCENE_SHAPES}" in message


def test_too_many_shapes_in_one_object(tmp_path: Path) -> None:
    n = MAX_SCENE_SHAPES + 1
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "collision_objects:\n  - id: rack\n"
        f"    primitives: [{', '.join(['{type: 2, dimensions: [0.01]}'] * n)}]\n"
        f"    primitive_poses: [{', '.join(['{position: {x: 2}}'] * n)}]\n"
    )
    field, message = _problem(scene)
    assert field == f"collision_objects[0].primitives[{MAX_SCENE_SHAPES}]"
    assert f"more than {MAX_SCENE_SHAPES} primitives and meshes" in message


@pytest.mark.parametrize(
    ("scale", "field"),
    [("[1e308, 1e308, 1e308]", "scale"), ("[1e6, 1, 1]", "scale"), ("[0, 1, 1]", "scale")],
)
def test_a_scale_that_overflows_is_one_problem(scale: str, field: str, tmp_path: Path) -> None:
    write_stl(tmp_path / "wall.stl", box_triangles((0.1, 0.1, 0.1)))
    scene = tmp_path / "scene.yaml"
    scene.write_text(_mesh_objects("wall.stl", 1, scale))
    got, _ = _problem(scene)  # pytest turns NumPy's overflow warning into an error
    assert got == f"collision_objects[0].meshes[0].{field}"


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ("primitives: [{type: box, dimensions: [1e308, 1, 1]}]\n    primitive_poses: [{}]",
         "primitives[0].dimensions"),
        ("primitives: [{type: 2, dimensions: [1]}]\n    primitive_poses: [{position: {x: 1e308}}]",
         "primitive_poses[0].position"),
        ("meshes: [{vertices: [{x: 1e308, y: 0, z: 0}, {x: 0, y: 1, z: 0}, {x: 0, y: 0, z: 1}],"
         " triangles: [{vertex_indices: [0, 1, 2]}]}]\n    mesh_poses: [{}]", "meshes[0].vertices"),
    ],
)  # fmt: skip
def test_coordinates_and_sizes_are_bounded(body: str, field: str, tmp_path: Path) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"collision_objects:\n  - id: a\n    {body}\n")
    got, message = _problem(scene)
    assert got == f"collision_objects[0].{field}" and "within ±10000 m" in message


def test_plan_with_a_huge_scale_or_goal_says_one_line(tmp_path: Path) -> None:
    """Before: NumPy overflow warnings on stderr, then an internal error or `closest: inf m`."""
    write_stl(tmp_path / "wall.stl", box_triangles((0.1, 0.1, 0.1)))
    scene = tmp_path / "scene.yaml"
    scene.write_text(_mesh_objects("wall.stl", 1, "[1e308, 1e308, 1e308]"))
    proc = run_cli(["plan", DEFAULT_SPEC, "--to", "reach", "--scene", scene], tmp_path)
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert "meshes[0].scale: the scaled vertices must stay within ±10000 m" in proc.stderr
    proc = run_cli(["plan", DEFAULT_SPEC, "--to-xyz", "1e308,0,0"], tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert (
        proc.stderr == "error: --to-xyz: each coordinate must be within ±10000 m, got '1e308,0,0'\n"
    )
