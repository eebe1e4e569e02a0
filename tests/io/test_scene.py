"""Scene files: moveit_msgs-shaped obstacles, and refusals naming file, line and field."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.errors import SpecError
from armcli.io.scene import load_scene

LINKS = ["base_link", "hand_link"]


def write(tmp_path: Path, text: str, name: str = "scene.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_solid_primitive_numbers_read_as_names(tmp_path: Path) -> None:
    by_number = write(tmp_path, """
collision_objects:
  - id: ball
    header: {frame_id: hand_link}
    primitives: [{type: 2, dimensions: [0.05]}]
    primitive_poses: [{position: {x: 0.1}}]
""")  # fmt: skip
    scene = load_scene(by_number, LINKS)
    (obj,) = scene.objects
    assert obj.frame == "hand_link"
    assert obj.shapes[0].kind == "sphere" and obj.shapes[0].dimensions == (0.05,)
    assert np.allclose(obj.shapes[0].T_frame_shape[:3, 3], [0.1, 0.0, 0.0])


def test_object_pose_composes_with_primitive_pose(tmp_path: Path) -> None:
    # object pose: 90° about z (quaternion z = w = sqrt(1/2)); primitive at x = 1 in it
    path = write(tmp_path, """
world:
  collision_objects:
    - id: b
      header: {frame_id: world}
      pose: {position: {x: 1.0}, orientation: {z: 0.7071067811865476, w: 0.7071067811865476}}
      primitives: [{type: box, dimensions: [0.1, 0.2, 0.3]}]
      primitive_poses: [{position: {x: 1.0}}]
""")  # fmt: skip
    (obj,) = load_scene(path, LINKS).objects
    assert obj.frame == ""
    assert np.allclose(obj.shapes[0].T_frame_shape[:3, 3], [1.0, 1.0, 0.0])


def test_mesh_file_inside_the_scene_directory(tmp_path: Path) -> None:
    import trimesh

    trimesh.creation.box(extents=(0.2, 0.2, 0.2)).export(tmp_path / "block.stl")
    path = write(tmp_path, """
collision_objects:
  - id: block
    meshes: [{path: block.stl, scale: [2, 2, 2]}]
    mesh_poses: [{}]
""")  # fmt: skip
    (obj,) = load_scene(path, LINKS).objects
    verts = obj.shapes[0].vertices
    assert verts is not None and np.allclose(np.abs(verts).max(axis=0), [0.2, 0.2, 0.2])


@pytest.mark.parametrize(
    ("body", "line", "field", "words"),
    [
        ("  - id: a\n    primitives: [{type: pyramid, dimensions: [1]}]\n"
         "    primitive_poses: [{}]\n", 3, "collision_objects[0].primitives[0].type",
         "unknown primitive"),
        ("  - id: a\n    primitives: [{type: box, dimensions: [1, 2]}]\n"
         "    primitive_poses: [{}]\n", 3, "collision_objects[0].primitives[0].dimensions",
         "needs 3"),
        ("  - id: a\n    header: {frame_id: moon}\n    primitives: [{type: 2, dimensions: [1]}]\n"
         "    primitive_poses: [{}]\n", 3, "collision_objects[0].header.frame_id", "unknown frame"),
        ("  - id: a\n    primitives: [{type: 2, dimensions: [.nan]}]\n"
         "    primitive_poses: [{}]\n", 3, "collision_objects[0].primitives[0].dimensions[0]",
         "finite"),
        ("  - id: a\n    primitives: [{type: 2, dimensions: [1]}]\n", 2,
         "collision_objects[0].primitive_poses", "one pose per entry"),
        ("  - id: a\n    meshes: [{path: ../secret.stl}]\n    mesh_poses: [{}]\n", 3,
         "collision_objects[0].meshes[0].path", "not a file inside"),
    ],
)  # fmt: skip
def test_bad_scene_names_file_line_and_field(
    tmp_path: Path, body: str, line: int, field: str, words: str
) -> None:
    (tmp_path.parent / "secret.stl").write_text("solid x\nendsolid x\n")
    path = write(tmp_path, "collision_objects:\n" + body)
    with pytest.raises(SpecError) as info:
        load_scene(path, LINKS)
    first = info.value.problems[0]
    assert (first.line, first.field) == (line, field)
    assert words in first.message
    assert str(path) in info.value.lines()[0]
