"""Meshes: resolved and confined by armcli, bounded, and never a crash (issue 15).

Each test failed before mesh_confine.py: Pinocchio got search directories and
`package://` URIs to resolve itself (reaching outside the allowed roots), any
parent folder named like a package was a root, coal crashed on mesh collision
pairs, trimesh gave up on large shapes, and two links of 5000 boxes hung check.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import trimesh

import armcli.robot.model
from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.io.mesh_confine import MAX_MESH_BYTES
from armcli.robot.load import collision_model
from armcli.spec.load import load_spec
from armcli.urdf.read import MAX_URDF_COLLISIONS, read_urdf
from tests.helpers import run_cli

PACKAGE_XML = "<?xml version='1.0'?>\n<package format='3'><name>{name}</name></package>\n"


def _arm(root: Path) -> str:
    return (root / "urdf" / "standalone_arm.urdf").read_text()


def _with_collision_meshes(text: str, forearm: str, hand: str) -> str:
    """The standalone arm with the collision shapes of forearm and hand made meshes."""
    for link, uri in (("forearm_link", forearm), ("hand_link", hand)):
        start = text.index("<collision>", text.index(f'<link name="{link}"'))
        g0 = text.index("<geometry>", start)
        g1 = text.index("</geometry>", start)
        text = text[:g0] + f'<geometry><mesh filename="{uri}"/>' + text[g1:]
    return text


def _package(tmp: Path, name: str = "robot_pkg", with_xml: bool = True) -> Path:
    pkg = tmp / name
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "meshes").mkdir()
    trimesh.creation.box(extents=(0.05, 0.05, 0.05)).export(pkg / "meshes" / "box.stl")
    if with_xml:
        (pkg / "package.xml").write_text(PACKAGE_XML.format(name=name))
    return pkg


def test_mesh_collision_pairs_do_not_crash(tmp_path: Path, root: Path) -> None:
    # coal: "Negative security margin are not handled yet for BVHModel" (internal error).
    pkg = _package(tmp_path)
    urdf = pkg / "urdf" / "arm.urdf"
    urdf.write_text(_with_collision_meshes(_arm(root), "../meshes/box.stl", "../meshes/box.stl"))
    spec = root / "specs" / "my_robot.yaml"
    proc = run_cli(["check", "--format", "json", "--spec", str(spec), str(urdf)], root)
    assert proc.returncode in (0, 1), proc.stderr
    assert "internal error" not in proc.stderr
    notes = json.dumps(json.loads(proc.stdout))
    assert "self-collision skipped" not in notes  # the meshes were really used


def test_pinocchio_gets_only_absolute_confined_paths(
    tmp_path: Path, root: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # robot_pkg/etc/robot_pkg -> outside: Pinocchio appended the URI path to each search
    # directory and so read outside/etc/passwd (strace showed /etc/passwd with a link to /).
    pkg = _package(tmp_path)
    (pkg / "etc").mkdir()
    trimesh.creation.box(extents=(0.05, 0.05, 0.05)).export(pkg / "etc" / "passwd", "stl")
    outside = tmp_path / "outside"
    (outside / "etc").mkdir(parents=True)
    (outside / "etc" / "passwd").write_text("secret")
    (pkg / "etc" / "robot_pkg").symlink_to(outside)
    urdf = pkg / "urdf" / "arm.urdf"
    urdf.write_text(
        _with_collision_meshes(_arm(root), "package://robot_pkg/etc/passwd", "../meshes/box.stl")
    )
    seen: list[str] = []
    real = collision_model  # what Robot.collision_model hands the xml to (no search dirs)

    def spy(model: Any, xml: str, source: str = "") -> Any:
        seen.append(xml)
        return real(model, xml, source)

    monkeypatch.setattr(armcli.robot.model, "collision_model", spy)
    opts = CheckOptions(spec=load_spec(root / "specs" / "my_robot.yaml"))
    check_urdf(read_urdf(urdf), opts)
    assert len(seen) == 1
    xml = seen[0]
    assert f'filename="{(pkg / "etc" / "passwd").resolve()}"' in xml
    assert f'filename="{(pkg / "meshes" / "box.stl").resolve()}"' in xml
    assert "package://" not in xml


def test_folder_name_alone_is_not_a_package_root(tmp_path: Path, root: Path) -> None:
    # Any parent folder named NAME was a root: `package://NAME/...` probed for files there.
    pkg = _package(tmp_path, "probe", with_xml=False)
    urdf = pkg / "urdf" / "arm.urdf"
    urdf.write_text(
        _with_collision_meshes(_arm(root), "package://probe/meshes/box.stl", "../meshes/box.stl")
    )
    proc = run_cli(["check", "--format", "json", str(urdf)], root)
    messages = [f["message"] for f in json.loads(proc.stdout)["files"][0]["findings"]]
    assert any("'package://probe/meshes/box.stl': unknown package" in m for m in messages)
    (pkg / "package.xml").write_text(PACKAGE_XML.format(name="probe"))
    proc = run_cli(["check", "--format", "json", str(urdf)], root)
    assert proc.returncode == 0, proc.stdout


def test_oversized_mesh_refused(tmp_path: Path, root: Path) -> None:
    pkg = _package(tmp_path)
    with (pkg / "meshes" / "huge.stl").open("wb") as fh:
        fh.truncate(MAX_MESH_BYTES + 1)  # sparse: no disk used
    text = _arm(root)
    start = text.index("<visual>", text.index('<link name="hand_link"'))
    g0, g1 = text.index("<geometry>", start), text.index("</geometry>", start)
    urdf = pkg / "urdf" / "arm.urdf"
    urdf.write_text(text[:g0] + '<geometry><mesh filename="../meshes/huge.stl"/>' + text[g1:])
    out = tmp_path / "robot.png"
    proc = run_cli(["render", str(urdf), "-o", str(out)], root)
    assert proc.returncode == 2, proc.stderr
    assert f"more than the {MAX_MESH_BYTES}-byte cap per mesh" in proc.stderr
    assert not out.exists()


@pytest.mark.parametrize(
    "geometry",
    ['<box size="10 10 10"/>', '<mesh filename="../meshes/box.stl" scale="250 250 250"/>'],
    ids=["box-10m", "mesh-x250"],
)
def test_render_large_shapes(geometry: str, tmp_path: Path, root: Path) -> None:
    # trimesh's subdivide_to_size raised "max_iter exceeded" (internal error).
    pkg = _package(tmp_path)
    text = _arm(root)
    start = text.index("<visual>", text.index('<link name="hand_link"'))
    g0, g1 = text.index("<geometry>", start), text.index("</geometry>", start)
    urdf = pkg / "urdf" / "arm.urdf"
    urdf.write_text(text[:g0] + f"<geometry>{geometry}" + text[g1:])
    out = tmp_path / "robot.png"
    proc = run_cli(["render", str(urdf), "-o", str(out), "--size", "300x200"], root)
    assert proc.returncode == 0, proc.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_collision_shape_count_bounded(tmp_path: Path, root: Path) -> None:
    # Two links with 5000 boxes each: check was still running after 300 s.
    boxes = "".join(
        f'<collision><origin xyz="{i * 1e-3} 0 0"/><geometry><box size="0.01 0.01 0.01"/>'
        "</geometry></collision>"
        for i in range(5000)
    )
    text = _arm(root)
    for link in ("forearm_link", "hand_link"):
        at = text.index(">", text.index(f'<link name="{link}"')) + 1
        text = text[:at] + boxes + text[at:]
    urdf = tmp_path / "boxes.urdf"
    urdf.write_text(text)
    spec = root / "specs" / "my_robot.yaml"
    proc = run_cli(["check", "--spec", str(spec), str(urdf)], root)
    assert proc.returncode == 2, proc.stderr
    assert f"more than {MAX_URDF_COLLISIONS} collision shapes (10003)" in proc.stderr


def test_ament_index_registered_share_dir_is_a_package_root(tmp_path: Path) -> None:
    """ROS 2 resolves package://NAME through the ament index (<prefix>/share/NAME), whatever
    package.xml says (example-robot-data's names example_robot_descriptions)."""
    from armcli.io.mesh_confine import is_package

    share = tmp_path / "prefix" / "share"
    pkg = share / "robot-data"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE_XML.format(name="robot_descriptions"))
    assert not is_package(pkg, "robot-data")  # neither package.xml nor the index says so
    marker = share / "ament_index" / "resource_index" / "packages" / "robot-data"
    marker.parent.mkdir(parents=True)
    marker.touch()
    assert is_package(pkg, "robot-data")
    assert not is_package(pkg, "other")
