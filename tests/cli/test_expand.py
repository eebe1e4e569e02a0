"""`armcli expand` and the xacro arguments of every command that reads xacro (issue 19).

Before: no command could pass xacro arguments (`armcli tree ur.urdf.xacro` ->
"undefined substitution argument 'name'"), and with only AMENT_PREFIX_PATH set
`$(find)` failed. Here the ros_ws fixture is installed as a sourced workspace and
every command is run through the real CLI.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import xacro

from tests.helpers import (
    ARM_PACKAGE,
    DEMO_ARM,
    ROOT,
    ROS_WS_SRC,
    ament_index_shim,
    run_cli,
    symlink_install,
)

TRAJECTORY = (
    "{joint_names: [l_shoulder, l_elbow], "
    "points: [{positions: [0.3, 0.2], time_from_start: {sec: 1}}]}"
)


@pytest.fixture(scope="module")
def prefix(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return symlink_install(ROS_WS_SRC, tmp_path_factory.mktemp("ws") / "install")


def armcli(prefix: Path, *args: str | Path, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    """The CLI with only AMENT_PREFIX_PATH set, as a sourced ROS 2 workspace leaves it."""
    env = {"AMENT_PREFIX_PATH": str(prefix), "COLUMNS": "200"}
    return run_cli(args, cwd, env, unset=("ROS_PACKAGE_PATH",), timeout=180)


def reference(
    prefix: Path, path: Path, args: dict[str, str], monkeypatch: pytest.MonkeyPatch
) -> bytes:
    """xacro itself on the same file, with ament_index_python stood in for."""
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    top, packages = ament_index_shim()
    monkeypatch.setitem(sys.modules, "ament_index_python", top)
    monkeypatch.setitem(sys.modules, "ament_index_python.packages", packages)
    out: bytes = xacro.process_file(str(path), mappings=dict(args)).toprettyxml(
        indent="  ", encoding="utf-8"
    )
    return out


def test_expand_equals_xacro_and_reports_arguments(
    prefix: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    top = prefix / "share" / ARM_PACKAGE / "urdf" / DEMO_ARM.name
    r = armcli(prefix, "expand", top, "name:=demo", "prefix:=l_")
    assert r.returncode == 0, r.stderr
    # absolute path given: even xacro's banner (which names the file) is the same
    assert r.stdout.encode() == reference(
        prefix, top, {"name": "demo", "prefix": "l_"}, monkeypatch
    )
    assert (
        "note: xacro arguments: given name:=demo, prefix:=l_; "
        "defaults taken arm_type:=short, with_gripper:=true" in r.stderr
    )
    assert "note: $(optenv) took its default for DEMO_ARM_TOOL_LENGTH" in r.stderr
    assert "warning: " in r.stderr and "inertials.yaml:12: duplicate YAML key 'upper'" in r.stderr
    out = tmp_path / "arm.urdf"
    r = armcli(prefix, "expand", top, "name:=demo", "--env", "DEMO_ARM_TOOL_LENGTH=0.1", "-o", out)
    assert r.returncode == 0, r.stderr
    assert r.stdout == "" and b'xyz="0 0 0.35"' in out.read_bytes()  # 0.25 m elbow + 0.1 m tool
    assert "$(optenv)" not in r.stderr


def test_missing_argument_is_one_line_naming_file_and_option(prefix: Path) -> None:
    r = armcli(prefix, "tree", DEMO_ARM)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr == (
        f"error: {DEMO_ARM}:4: undefined xacro argument 'name': pass name:=VALUE after the file\n"
    )
    r = armcli(prefix, "tree", DEMO_ARM, "name:=demo", "extra.urdf")
    assert r.returncode == 2 and "only xacro arguments NAME:=VALUE may follow" in r.stderr


@pytest.mark.parametrize(
    "command",
    [
        ["tree"],
        ["check"],
        ["render", "--size", "300x200", "-o", "{tmp}/arm.png"],
        ["export", "mjcf", "-o", "{tmp}/arm.xml"],
        ["simulate", "-m", TRAJECTORY, "--kp", "50", "--kd", "5", "--duration", "1.2", "--urdf"],
    ],
    ids=lambda c: c[0],
)
def test_every_command_takes_xacro_arguments(
    command: list[str], prefix: Path, tmp_path: Path
) -> None:
    args = [c.replace("{tmp}", str(tmp_path)) for c in command]
    r = armcli(prefix, *args, DEMO_ARM, "name:=demo", "prefix:=l_")
    assert r.returncode == 0, r.stderr
    assert "note: " in r.stderr and "given name:=demo, prefix:=l_" in r.stderr
    if command[0] == "tree":
        assert "l_finger_link" in r.stdout and "l_shoulder" in r.stdout
    if command[0] == "check":  # the file:// and package:// meshes of the install resolve
        assert "mesh-missing" not in r.stdout and "0 error(s)" in r.stdout


@pytest.mark.parametrize("how", ["same path", "symlink", "hard link"])
def test_expand_never_writes_over_its_input(how: str, tmp_path: Path) -> None:
    """Issue 27: `armcli expand a.xacro -o a.xacro` replaced the xacro by its expansion."""
    from tests.helpers import run_cli

    src = tmp_path / "a.xacro"
    text = '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="l"/></robot>'
    src.write_text(text)
    out = src
    if how == "symlink":
        out = tmp_path / "link.urdf"
        out.symlink_to(src)
    elif how == "hard link":
        out = tmp_path / "hard.urdf"
        out.hardlink_to(src)
    proc = run_cli(["expand", src, "-o", out])
    assert proc.returncode == 2 and "is the input file" in proc.stderr, proc.stderr
    assert src.read_text() == text
