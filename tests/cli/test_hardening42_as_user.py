"""Issue 42's file cases through the real CLI, as the invoking user (root on CI) and as an
ordinary user (tests/cli/conftest.py): a scene's OBJ material library and glTF buffer
that are FIFOs (they hung the scene reader), a spec whose name reads like a DOCTYPE (it
no longer built). The journal and `-o`-over-input cases are in test_journal_writers.py
and test_output_over_input.py, the viewer's other user in tests/view/test_token.py."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from tests.helpers import DEFAULT_SPEC
from tests.io.test_doctype import HOSTILE_NAME
from tests.urdf.ordinary_user import Run

WALL_OBJ = "mtllib wall.mtl\nv 1 0 0.5\nv 1 0.1 0.5\nv 1 0 0.6\nusemtl a\nf 1 2 3\n"


def _scene(work: Path, mesh: str) -> Path:
    scene = work / "scene.yaml"
    scene.write_text(
        "collision_objects:\n  - id: wall\n"
        f"    meshes: [{{path: {mesh}}}]\n    mesh_poses: [{{position: {{x: 1.0}}}}]\n"
    )
    return scene


def test_a_fifo_beside_a_scene_mesh_is_never_opened(run: tuple[Path, Run]) -> None:
    work, cli = run
    shutil.copy(DEFAULT_SPEC, work / "robot.yaml")
    os.mkfifo(work / "wall.mtl")
    (work / "wall.obj").write_text(WALL_OBJ)
    proc = cli("plan", work / "robot.yaml", "--to", "reach", "--scene", _scene(work, "wall.obj"))
    assert proc.returncode == 0, proc.stderr  # before: blocked on wall.mtl (timeout)


def test_a_gltf_buffer_fifo_is_refused_without_blocking(run: tuple[Path, Run]) -> None:
    import trimesh

    work, cli = run
    shutil.copy(DEFAULT_SPEC, work / "robot.yaml")
    for name, data in trimesh.exchange.gltf.export_gltf(trimesh.creation.box()).items():
        path = work / ("wall.gltf" if name == "model.gltf" else name)
        if name.endswith(".bin"):
            os.mkfifo(path)
        else:
            path.write_bytes(data)
    proc = cli("plan", work / "robot.yaml", "--to", "reach", "--scene", _scene(work, "wall.gltf"))
    assert proc.returncode == 2, proc.stderr
    assert (
        "a glTF whose data is in other files" in proc.stderr and len(proc.stderr.splitlines()) == 1
    )


def test_a_spec_named_like_a_doctype_builds(run: tuple[Path, Run]) -> None:
    work, cli = run
    spec = work / HOSTILE_NAME
    shutil.copy(DEFAULT_SPEC, spec)
    proc = cli("build", spec, "-o", work / "out")
    assert proc.returncode == 0, proc.stderr
    proc = cli("check", work / "out" / "my_robot.urdf")
    assert proc.returncode == 0, proc.stderr
