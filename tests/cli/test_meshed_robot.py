"""import -> check -> ros-package at once for a robot whose meshes are `package://` URIs
(issue 31, as OpenManipulator-X: its clone directory is not named after its package).

Before: `check` of the imported spec reported every mesh `unknown package` (exit 1),
`ros-package` had no `--package-dir` and died with `internal error: ValueError` from
Pinocchio's geometry loader, and a relative `--package-dir` started at the xacro's
directory (the safe expander's child runs there).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from armcli.spec.load import load_spec
from tests.helpers import FIXTURES, run_main

CLONE = FIXTURES / "meshed" / "mesh_arm_clone"
PACKAGE = "mesh_arm_description"


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A working directory holding the clone (`ws/`) and nothing on the ROS paths."""
    shutil.copytree(CLONE, tmp_path / "ws" / "mesh_arm_clone")
    monkeypatch.chdir(tmp_path)
    for var in ("AMENT_PREFIX_PATH", "ROS_PACKAGE_PATH"):
        monkeypatch.delenv(var, raising=False)
    return tmp_path


def test_import_check_ros_package_at_once(
    project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = Path("proj", "arm.yaml")
    code, out, err = run_main(
        ["import", "ws/mesh_arm_clone/urdf/mesh_arm.urdf", "-o", spec], capsys
    )
    assert code == 0, err
    # recorded relative to the spec, so the project can move as a whole
    assert load_spec(spec).packages == {PACKAGE: "../ws/mesh_arm_clone"}
    code, out, err = run_main(["check", spec], capsys)
    assert code == 0, out + err
    assert "mesh-missing" not in out and "0 error(s), 0 warning(s)" in out  # start gains pass
    code, out, err = run_main(["ros-package", spec, "-o", "proj/ros", "--samples", "50"], capsys)
    assert code == 0, err
    assert "internal error" not in err
    # plan reads the spec's recorded packages too (it used only --package-dir and the
    # environment: "mesh 'package://mesh_arm_description/...' cannot be found")
    code, out, err = run_main(["plan", spec, "--from", "0,0", "--to", "0.5,0.5",
                               "-o", "proj/t.yaml"], capsys)  # fmt: skip
    assert code == 0, err
    assert Path("proj", "t.yaml").is_file()


def test_missing_mesh_is_an_input_error_naming_the_option(
    project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run_main(
        ["import", "ws/mesh_arm_clone/urdf/mesh_arm.urdf", "-o", "a.yaml"], capsys
    )
    assert code == 0, err
    text = Path("a.yaml").read_text()
    assert f"packages: {{{PACKAGE}: ws/mesh_arm_clone}}" in text
    Path("a.yaml").write_text(text.replace(": ws/mesh_arm_clone}", ": elsewhere}"))
    code, _, err = run_main(["ros-package", "a.yaml", "-o", "ros"], capsys)
    assert code == 2 and "packages.mesh_arm_description" in err  # the recorded path is wrong
    Path("a.yaml").write_text("\n".join(ln for ln in text.splitlines() if "packages" not in ln))
    code, _, err = run_main(["ros-package", "a.yaml", "-o", "ros", "--samples", "20"], capsys)
    assert code == 2 and "internal error" not in err and len(err.strip().splitlines()) == 1
    assert f"package://{PACKAGE}/meshes/link.stl" in err
    assert f"--package-dir {PACKAGE}=PATH" in err
    given = ["--package-dir", f"{PACKAGE}=ws/mesh_arm_clone"]  # relative to the cwd
    code, _, err = run_main(
        ["ros-package", "a.yaml", "-o", "ros", "--samples", "20", *given], capsys
    )
    assert code == 0, err
    code, out, _ = run_main(["check", "a.yaml"], capsys)
    assert code == 1 and f"--package-dir {PACKAGE}=PATH" in out  # check's finding says so too


def test_relative_package_dir_starts_at_the_working_directory(
    project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    xacro = Path("robots", "arm.urdf.xacro")
    xacro.parent.mkdir()
    xacro.write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">'
        f'<link name="$(find {PACKAGE})"/></robot>'
    )
    given = ["--package-dir", f"{PACKAGE}=ws/mesh_arm_clone"]
    code, _, err = run_main(["expand", xacro, "-o", "r.urdf", *given], capsys)
    assert code == 0, err
    # the absolute path of ./ws/mesh_arm_clone, not of robots/ws/mesh_arm_clone
    assert f'name="{project / "ws" / "mesh_arm_clone"}"' in Path("r.urdf").read_text()
    code, _, err = run_main(["expand", xacro, "--package-dir", f"{PACKAGE}=nowhere"], capsys)
    assert code == 2 and "--package-dir" in err and "nowhere is not a directory" in err


def test_relative_ros_package_path_starts_at_the_working_directory(
    project: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    xacro = Path("robots", "arm.urdf.xacro")
    xacro.parent.mkdir()
    xacro.write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">'
        f'<link name="$(find {PACKAGE})"/></robot>'
    )
    monkeypatch.setenv("ROS_PACKAGE_PATH", "ws")  # crawled from here, not from robots/
    code, _, err = run_main(["expand", xacro, "-o", "r.urdf"], capsys)
    assert code == 0, err
    assert f'name="{project / "ws" / "mesh_arm_clone"}"' in Path("r.urdf").read_text()
