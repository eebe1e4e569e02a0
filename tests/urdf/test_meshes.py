"""armcli.urdf.meshes.confined_mesh_xml: the one route from a URDF's mesh URIs to the files
Pinocchio reads, taken by the robot model (`check`, `plan`: `Robot.collision_model`) and by
`ros-package` (its collision matrix, from a spec's directory, collision meshes only).

Both callers resolve a mesh to the same real file and refuse the same hostile URIs with the
same message: a package path climbing out of its package, absolute and `file://` paths
outside the roots, a symlink pointing out, an unknown package.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from armcli.errors import InputError
from armcli.io import mesh_confine
from armcli.robot.model import Robot
from armcli.urdf.meshes import MeshSearch, confined_mesh_xml
from armcli.urdf.read import parse_urdf
from tests.meshes import prism_triangles, write_stl

URDF = """<robot name="r">
  <link name="base">
    <visual><geometry><mesh filename="{visual}"/></geometry></visual>
    <collision><geometry><mesh filename="{collision}"/></geometry></collision>
  </link>
</robot>"""
SEARCH = MeshSearch(ament_prefixes=(), ros_package_path=())  # no environment: the package only


@pytest.fixture
def pkg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Package `x` (ws/x: urdf/, meshes/box.stl, meshes/innocent.stl -> ../../../host) and
    host/secret.stl outside it, a valid mesh so that only its place is wrong."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    pkg = tmp_path / "ws" / "x"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>x</name></package>")
    write_stl(pkg / "meshes" / "box.stl", prism_triangles(0.05, 0.1, 4))
    secret = write_stl(tmp_path / "host" / "secret.stl", prism_triangles(0.05, 0.1, 4))
    (pkg / "meshes" / "innocent.stl").symlink_to(secret)
    return pkg


def _text(uri: str, visual: str | None = None) -> bytes:
    return URDF.format(visual=uri if visual is None else visual, collision=uri).encode()


def _robot_route(pkg: Path, uri: str) -> list[str]:
    """The collision mesh files Pinocchio loaded for `check` and `plan` (the URDF in urdf/)."""
    source = pkg / "urdf" / "r.urdf"
    source.write_bytes(_text(uri))
    gm = Robot.load(parse_urdf(_text(uri), str(source))).collision_model(SEARCH)
    return [g.meshPath for g in gm.geometryObjects]


def _ros_route(pkg: Path, uri: str, visual: str | None = None) -> list[str]:
    """The collision mesh files as `ros_packages` hands them on (a spec in urdf/)."""
    spec = pkg / "urdf" / "armcli.yaml"
    text = confined_mesh_xml(
        _text(uri, visual), str(spec), SEARCH, base_dir=spec.parent, collision_only=True
    )
    root = etree.fromstring(text.encode())
    return [m.get("filename", "") for c in root.iter("collision") for m in c.iter("mesh")]


@pytest.mark.parametrize(
    "uri", ["../meshes/box.stl", "package://x/meshes/box.stl", "file://{pkg}/meshes/box.stl"]
)
def test_both_routes_resolve_a_mesh_to_the_same_file(pkg: Path, uri: str) -> None:
    uri = uri.format(pkg=pkg)
    real = str((pkg / "meshes" / "box.stl").resolve())
    assert _robot_route(pkg, uri) == _ros_route(pkg, uri) == [real]


HOSTILE = [
    "package://x/../../host/secret.stl",  # climbs out of the package
    "{host}/secret.stl",  # absolute, outside every root
    "file://{host}/secret.stl",
    "../../../host/secret.stl",  # relative, out of the URDF's directory
    "../meshes/innocent.stl",  # a symlink inside the package pointing out
]


@pytest.mark.parametrize("uri", [*HOSTILE, "package://nope/meshes/box.stl", "../meshes/gone.stl"])
def test_both_routes_refuse_the_same_hostile_mesh(pkg: Path, uri: str) -> None:
    host = pkg.parent.parent / "host"
    uri = uri.format(host=host)
    with pytest.raises(InputError) as robot:
        _robot_route(pkg, uri)
    with pytest.raises(InputError) as ros:
        _ros_route(pkg, uri)
    assert robot.value.message == ros.value.message
    assert robot.value.message.startswith(f"mesh {uri!r} cannot be found (")
    if uri in [h.format(host=host) for h in HOSTILE]:  # refused for its place: the file is there
        named = robot.value.message.split("(no file ")[1].split(")")[0]
        assert Path(named).resolve() == (host / "secret.stl").resolve()


def test_both_routes_keep_the_total_mesh_bound(pkg: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(mesh_confine, "MAX_MESH_TOTAL_BYTES", 10)
    for route in (_robot_route, _ros_route):
        with pytest.raises(InputError, match="more than the 10-byte cap"):
            route(pkg, "../meshes/box.stl")


def test_only_the_ros_route_leaves_visual_meshes_as_written(pkg: Path) -> None:
    """`ros-package` loads collision geometry only: a visual mesh of a package not installed
    here stays a URI; the robot model requires every mesh of the document."""
    visual = "package://vendor/meshes/look.dae"
    spec = pkg / "urdf" / "armcli.yaml"
    text = confined_mesh_xml(
        _text("../meshes/box.stl", visual), str(spec), SEARCH, base_dir=spec.parent,
        collision_only=True,
    )  # fmt: skip
    assert f'filename="{visual}"' in text
    assert f'filename="{(pkg / "meshes" / "box.stl").resolve()}"' in text
    with pytest.raises(InputError, match=r"mesh 'package://vendor/\S+' cannot be found"):
        confined_mesh_xml(_text("../meshes/box.stl", visual), str(spec), SEARCH)
