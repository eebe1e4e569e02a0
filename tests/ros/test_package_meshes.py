"""`ros-package` copies the spec's meshes into the description package and names them
`package://`; meshes already in other packages keep their URIs and become dependencies."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pinocchio as pin
import pytest
from catkin_pkg.package import parse_package_string
from lxml import etree

from armcli.errors import InputError
from armcli.ros.packages import ros_packages
from armcli.spec.load import load_spec
from tests.compiler.test_acceptance import SPEC, write_meshes
from tests.meshes import prism_triangles, write_stl

DESC = "rich_arm_description"


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    project = tmp_path_factory.mktemp("pkgmeshes")
    shutil.copy(SPEC, project / "armcli.yaml")
    write_meshes(project)
    return project


@pytest.fixture(scope="module")
def files(project: Path) -> dict[str, bytes]:
    return dict(ros_packages(load_spec(project / "armcli.yaml"), samples=50).files)


def test_meshes_are_copied_byte_for_byte(project: Path, files: dict[str, bytes]) -> None:
    for name in ("base.stl", "link.stl"):
        assert files[f"{DESC}/meshes/{name}"] == (project / "meshes" / name).read_bytes()
    assert "DIRECTORY launch meshes rviz urdf" in files[f"{DESC}/CMakeLists.txt"].decode()


def test_xacro_names_them_by_package(files: dict[str, bytes]) -> None:
    arm = etree.fromstring(files[f"{DESC}/urdf/arm.xacro"])
    uris = {m.get("filename") for m in arm.iter("mesh")}
    assert uris == {f"package://{DESC}/meshes/base.stl", f"package://{DESC}/meshes/link.stl"}


def test_the_installed_description_loads_in_pinocchio(
    files: dict[str, bytes], tmp_path: Path
) -> None:
    import xacro

    share = tmp_path / "share"
    for rel, data in files.items():
        if rel.startswith(DESC + "/"):
            (share / rel).parent.mkdir(parents=True, exist_ok=True)
            (share / rel).write_bytes(data)
    doc = xacro.process_file(str(share / DESC / "urdf" / "standalone_arm.urdf.xacro"))
    xml = doc.toprettyxml()
    model = pin.buildModelFromXML(xml)
    geom = pin.buildGeomFromUrdfString(
        model, xml, pin.GeometryType.VISUAL, package_dirs=[str(share)]
    )
    meshes = [g.meshPath for g in geom.geometryObjects if g.meshPath.endswith(".stl")]
    assert meshes and all(m.startswith(str(share / DESC / "meshes")) for m in meshes)


def test_packaged_meshes_are_deterministic(project: Path, files: dict[str, bytes]) -> None:
    again = dict(ros_packages(load_spec(project / "armcli.yaml"), samples=50).files)
    assert again == files


def test_other_packages_meshes_stay_and_become_dependencies(project: Path, tmp_path: Path) -> None:
    text = (
        (project / "armcli.yaml")
        .read_text()
        .replace("filename: meshes/base.stl", "filename: package://vendor_meshes/meshes/base.dae")
    )
    (tmp_path / "armcli.yaml").write_text(text)
    write_meshes(tmp_path)
    got = ros_packages(load_spec(tmp_path / "armcli.yaml"), samples=50).files
    manifest = parse_package_string(got[f"{DESC}/package.xml"].decode())
    assert "vendor_meshes" in {d.name for d in manifest.exec_depends}
    assert f"{DESC}/meshes/base.stl" not in got
    arm = got[f"{DESC}/urdf/arm.xacro"].decode()
    assert "package://vendor_meshes/meshes/base.dae" in arm


def test_two_files_on_one_package_path_are_refused(project: Path, tmp_path: Path) -> None:
    write_meshes(tmp_path)
    (tmp_path / "other" / "meshes").mkdir(parents=True)
    shutil.copy(project / "meshes" / "link.stl", tmp_path / "other" / "meshes" / "base.stl")
    shoulder = "geometry: {mesh: {filename: meshes/link.stl, scale: [1, 1, 0.8]}}"
    text = (project / "armcli.yaml").read_text()
    text = text.replace("filename: meshes/base.stl", "filename: other/meshes/base.stl", 1)
    text = text.replace(shoulder, "geometry: {mesh: {filename: meshes/base.stl}}", 1)
    (tmp_path / "armcli.yaml").write_text(text)
    with pytest.raises(InputError, match=r"would both be copied to meshes/base\.stl"):
        ros_packages(load_spec(tmp_path / "armcli.yaml"), samples=50)


def _hostile_project(tmp: Path, mesh: str | None = None, texture: str | None = None) -> Path:
    """rich_arm in tmp/project with its base mesh named `mesh` and/or a grey `texture`."""
    project = tmp / "project"
    project.mkdir()
    text = SPEC.read_text()
    if mesh is not None:
        text = text.replace("filename: meshes/base.stl", f"filename: {mesh!r}")
    if texture is not None:
        text = text.replace("gazebo: Gazebo/Grey}", f"gazebo: Gazebo/Grey, texture: {texture!r}}}")
    (project / "armcli.yaml").write_text(text)
    write_meshes(project)
    return project


def _secret(tmp: Path) -> Path:
    """A host file outside the project, shaped as a valid mesh so only its place is wrong."""
    secret = tmp / "host" / "secret.stl"
    secret.parent.mkdir()
    write_stl(secret, prism_triangles(0.08, 0.1, 32))
    return secret


@pytest.mark.parametrize("how", ["absolute", "relative", "symlink", "texture"])
def test_host_files_are_never_copied(how: str, tmp_path: Path) -> None:
    """Issue 27: a mesh or texture resolving outside the spec's directory is refused by name."""
    secret = _secret(tmp_path)
    if how == "absolute":
        project = _hostile_project(tmp_path, mesh=str(secret))
    elif how == "relative":
        project = _hostile_project(tmp_path, mesh="../host/secret.stl")
    elif how == "texture":
        project = _hostile_project(tmp_path, texture="../host/secret.stl")
    else:
        project = _hostile_project(tmp_path, mesh="meshes/innocent.stl")
        (project / "meshes" / "innocent.stl").symlink_to(secret)
    with pytest.raises(InputError) as info:
        ros_packages(load_spec(project / "armcli.yaml"), samples=10)
    line = str(info.value)
    assert "\n" not in line and "outside" in line
    assert "secret.stl" in line or "innocent.stl" in line


def test_a_fifo_mesh_is_refused(tmp_path: Path) -> None:
    project = _hostile_project(tmp_path, mesh="meshes/pipe.stl")
    os.mkfifo(project / "meshes" / "pipe.stl")
    with pytest.raises(InputError, match=r"pipe\.stl"):
        ros_packages(load_spec(project / "armcli.yaml"), samples=10)


def test_a_mesh_over_the_size_bound_is_not_copied(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from armcli.ros import copying

    project = _hostile_project(tmp_path)
    size = (project / "meshes" / "base.stl").stat().st_size
    monkeypatch.setattr(copying, "MAX_MESH_BYTES", size - 1)  # the cap is 20 MB: shrunk here
    with pytest.raises(InputError, match=r"base\.stl.*larger than"):
        ros_packages(load_spec(project / "armcli.yaml"), samples=10)


def test_a_compressed_collision_mesh_bomb_is_refused(tmp_path: Path) -> None:
    """The collision matrix loads collision meshes: they pass the same bounds as check's."""
    import gzip

    project = _hostile_project(tmp_path)
    stl = b"\0" * 80 + (800_000).to_bytes(4, "little") + b"\0" * (50 * 800_000)  # 40 MB
    (project / "meshes" / "bomb.stl").write_bytes(gzip.compress(stl, 1))
    text = (project / "armcli.yaml").read_text()
    text = text.replace(
        "geometry: {cylinder: {radius: 0.08, length: 0.1}}",
        "geometry: {mesh: {filename: meshes/bomb.stl}}",
    ).replace(
        "inertial: {shape: collision, mass: 4}",
        "inertial: {mass: 4, inertia: {ixx: 0.01, iyy: 0.01, izz: 0.01}}",
    )
    (project / "armcli.yaml").write_text(text)
    with pytest.raises(InputError, match="decompresses"):
        ros_packages(load_spec(project / "armcli.yaml"), samples=10)
