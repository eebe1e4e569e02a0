"""Issue 27's file cases through the real CLI, as the invoking user (root on CI) and as an
ordinary user: a passthrough include, a host mesh copied by ros-package, a package whose
share dir links to `/`. The refusal must come from armcli's rules, for both (an ordinary
user could not read root's files anyway, so each secret is readable by both)."""

from __future__ import annotations

from pathlib import Path

from tests.compiler.test_acceptance import SPEC as RICH_SPEC
from tests.compiler.test_acceptance import write_meshes
from tests.helpers import SPECS
from tests.meshes import prism_triangles, write_stl
from tests.urdf.ordinary_user import Run

SECRET = "s3cret-token"


def _secret(work: Path) -> Path:
    secret = work / "host" / "secret.xml"
    secret.parent.mkdir()
    secret.write_text(f'<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><{SECRET}/></robot>')
    secret.chmod(0o644)
    return secret


def test_passthrough_include_never_runs(run: tuple[Path, Run]) -> None:
    work, cli = run
    secret = _secret(work)
    spec = work / "robot.yaml"
    element = f'<gazebo xmlns:xacro="urn:x"><xacro:include filename="{secret}"/></gazebo>'
    spec.write_text((SPECS / "my_robot.yaml").read_text() + f"passthrough:\n  - '{element}'\n")
    proc = cli("build", spec, "-o", "out")
    assert proc.returncode == 2 and "passthrough[0]" in proc.stderr, proc.stderr
    assert SECRET not in proc.stdout + proc.stderr and not (work / "out").exists()


def test_ros_package_copies_no_host_file(run: tuple[Path, Run]) -> None:
    work, cli = run
    secret = work / "host" / "secret.stl"
    secret.parent.mkdir()
    write_stl(secret, prism_triangles(0.08, 0.1, 32))
    project = work / "project"
    project.mkdir()
    text = RICH_SPEC.read_text().replace(
        "filename: meshes/base.stl", "filename: ../host/secret.stl"
    )
    (project / "armcli.yaml").write_text(text)
    write_meshes(project)
    proc = cli("ros-package", project / "armcli.yaml", "-o", work / "ros", "--samples", "10")
    assert proc.returncode == 2 and "not copied into the package" in proc.stderr, proc.stderr
    assert not (work / "ros").exists()


def test_a_package_linked_to_slash_reads_nothing(run: tuple[Path, Run]) -> None:
    work, cli = run
    secret = _secret(work)
    prefix = work / "prefix"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "evil").write_text("")
    (prefix / "share" / "evil").symlink_to("/")
    robot = work / "robot"
    robot.mkdir()
    top = robot / "r.urdf.xacro"
    top.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        f'<xacro:include filename="$(find evil){secret}"/><link name="l"/></robot>'
    )
    proc = cli("expand", top, env={"AMENT_PREFIX_PATH": str(prefix)})
    assert proc.returncode == 2 and "outside the allowed directories" in proc.stderr, proc.stderr
    assert SECRET not in proc.stdout
