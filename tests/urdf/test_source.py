"""robot_source: one loader for every robot file argument (spec, URDF, xacro) and mesh roots."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from armcli.errors import InputError, XacroRefusedError
from armcli.io.packages import PackageLookup
from armcli.robot.model import Robot
from armcli.urdf.source import (
    Trust,
    allowed_roots,
    expand_xacro,
    inside_roots,
    read_robot,
    read_urdf_file,
)
from armcli.xacro.args import XacroInputs
from armcli.xacro.jail import sandbox_problem
from tests.helpers import (
    ARM_PACKAGE,
    DEFAULT_SPEC,
    DEMO_ARM,
    ROOT,
    ROS_WS_SRC,
    run_main,
    symlink_install,
)

COURSE_XACRO = ROOT / "tests" / "fixtures" / "check" / "course_macros.urdf.xacro"
BAD = ROOT / "tests" / "bad_inputs"
ARM_MASS_KG = 0.5 + 0.3 + 0.3  # spec: arm_base_link + forearm_link + hand_link masses
MASS_TOL = 1e-12


def test_spec_gives_both_urdfs_and_the_whole_robot(default_spec_path: Path) -> None:
    robot = read_robot(default_spec_path)
    names = [u.source.rsplit("#", 1)[1] for u in robot.urdfs]
    assert names == ["my_robot.urdf", "standalone_arm.urdf"]
    assert robot.spec is not None and robot.robot.source.endswith("#my_robot.urdf")


def test_urdf_is_read_strictly(root: Path) -> None:
    robot = read_robot(root / "urdf" / "standalone_arm.urdf")
    assert robot.spec is None and robot.robot.name == "standalone_arm"
    with pytest.raises(InputError, match="DOCTYPE"):
        read_robot(BAD / "urdf" / "external_entity.urdf")


def test_directory_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="is a directory"):
        read_robot(tmp_path)


@pytest.mark.parametrize("name", ["robot.urdf.xacro", "robot.urdf"])
def test_foreign_xacro_safe_by_suffix_or_content(tmp_path: Path, name: str) -> None:
    path = tmp_path / name
    path.write_bytes(COURSE_XACRO.read_bytes())
    safe = read_urdf_file(path)  # xacro_safe: no code from the file runs
    trusted = read_urdf_file(path, trust_xacro=True)  # xacro itself, in xacro_sandbox
    assert safe.source == trusted.source == f"{path}#expanded"
    assert safe.text == trusted.text
    assert {j.name for j in safe.joints} >= {"arm_base_forearm_joint", "forearm_hand_joint"}


def test_robot_load_refuses_what_pinocchio_would_accept(root: Path) -> None:
    with pytest.raises(InputError, match=r"nan_mass\.urdf:\d+: .*mass@value: non-finite"):
        Robot.load(read_urdf_file(BAD / "urdf" / "nan_mass.urdf"))
    with pytest.raises(InputError, match="not a number: '0x1p-1'"):
        Robot.load(read_urdf_file(BAD / "urdf" / "hex_number.urdf"))
    with pytest.raises(XacroRefusedError):
        Robot.load(read_urdf_file(BAD / "xacro" / "eval_exploit_renamed.urdf"))
    loaded = Robot.load(read_urdf_file(root / "urdf" / "standalone_arm.urdf"))
    assert loaded.model.nq == 2
    assert abs(sum(i.mass for i in loaded.model.inertias) - ARM_MASS_KG) < MASS_TOL


def test_allowed_roots_include_the_ros_package(tmp_path: Path) -> None:
    pkg = tmp_path / "my_pkg"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "meshes").mkdir()
    (pkg / "package.xml").write_text("<package/>")
    roots = allowed_roots(pkg / "urdf")
    assert inside_roots(pkg / "urdf" / ".." / "meshes" / "arm.stl", roots)
    assert not inside_roots(tmp_path / "elsewhere.stl", roots)
    assert not inside_roots(Path("/etc/passwd"), roots)


def test_inside_roots_follows_symlinks_and_dotdot(tmp_path: Path) -> None:
    here = tmp_path / "robot"
    here.mkdir()
    (here / "escape.stl").symlink_to("/etc/passwd")
    roots = allowed_roots(here)
    assert not inside_roots(here / "escape.stl", roots)
    assert not inside_roots(here / ".." / ".." / "etc" / "shadow", roots)
    assert inside_roots(here / "sub" / ".." / "ok.stl", roots)


def test_ros_package_path_entries_are_roots(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    monkeypatch.setenv("ROS_PACKAGE_PATH", os.pathsep.join([str(shared), ""]))
    assert inside_roots(shared / "pkg" / "mesh.stl", allowed_roots(tmp_path / "robot"))


@pytest.mark.parametrize(
    "command",
    [
        "check",
        "view",
        "render",
        "tree",
        "simulate",
    ],
)
def test_every_robot_file_command_offers_trust_xacro(command: str) -> None:
    from typer.testing import CliRunner

    from armcli.cli import app

    result = CliRunner().invoke(app, [command, "--help"])
    assert result.exit_code == 0, result.output
    assert "--trust-xacro" in result.output


# --- issue 19: --trust-xacro resolves $(find) and takes arguments ------------------------

TRUST_MODES = [
    pytest.param("unsandboxed", id="unsandboxed"),
    pytest.param(
        True,
        id="bubblewrap",
        marks=pytest.mark.skipif(sandbox_problem() is not None, reason=str(sandbox_problem())),
    ),
]


@pytest.mark.parametrize("trust", TRUST_MODES)
def test_trusted_xacro_finds_packages_through_the_ament_prefix(
    trust: Trust, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Was: "ModuleNotFoundError: No module named 'ament_index_python'" for every $(find).
    prefix = symlink_install(ROS_WS_SRC, tmp_path / "install")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    inputs = XacroInputs(args={"name": "demo", "nope": "1"}, env={"DEMO_ARM_TOOL_LENGTH": "0.1"})
    top = prefix / "share" / ARM_PACKAGE / "urdf" / DEMO_ARM.name
    trusted, used = expand_xacro(top, trust_xacro=trust, inputs=inputs)
    safe, _ = expand_xacro(top, inputs=inputs)
    assert trusted == safe and b'xyz="0 0 0.35"' in trusted  # --env reached $(optenv)
    assert used.given == ("name", "nope") and used.unused == ("nope",)
    assert set(used.defaults) == {"prefix", "arm_type", "with_gripper"}


def test_trusted_xacro_unknown_package_and_refused_env(tmp_path: Path) -> None:
    top = tmp_path / "find.xacro"
    top.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<link name="$(find no_such_pkg)"/></robot>'
    )
    lookup = PackageLookup(ament_prefixes=(), ros_package_path=())
    with pytest.raises(InputError, match="package 'no_such_pkg' not found by armcli"):
        expand_xacro(top, trust_xacro="unsandboxed", inputs=XacroInputs(packages=lookup))
    env = XacroInputs(env={"LD_PRELOAD": "/tmp/x.so"})
    with pytest.raises(InputError, match="--env: LD_PRELOAD may not be set"):
        expand_xacro(top, trust_xacro="unsandboxed", inputs=env)


def test_simulate_runs_xacro_once(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`simulate` needs the standalone arm and the whole robot (its zero-moment point): one
    expansion of the spec's xacro set gives both (issue 28: it used to run four)."""
    from armcli.compiler import expand
    from armcli.xacro.safe import expand_safe as real

    expanded: list[str] = []

    def counting(path: Path, *args: object, **kwargs: object) -> bytes:
        expanded.append(path.name)
        return real(path, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(expand, "expand_safe", counting)
    code, out, _ = run_main(["simulate", DEFAULT_SPEC, "--trajectory",
                             ROOT / "specs" / "trajectories" / "pick.yaml"], capsys)  # fmt: skip
    assert code == 0 and "zero-moment point" in out  # the whole robot was used too
    assert sorted(expanded) == ["my_robot.urdf.xacro", "standalone_arm.urdf.xacro"]
