"""`armcli check` through the real CLI in a subprocess: exit codes, formats, options."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from tests.helpers import ROOT, course_gains_spec, run_cli

FIXTURES = ROOT / "tests" / "fixtures" / "check"
HAND_TIP_HOME = [0.15, 0.0, 0.92]  # the forward-kinematics reference [m]
FK_ATOL = 1e-9


def armcli(*args: str | Path, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    return run_cli(args, cwd, {"COLUMNS": "200"})  # wide: one table row per line


def broken_copy(tmp_path: Path, old: str, new: str, name: str = "broken.urdf") -> Path:
    text = (ROOT / "urdf" / "my_robot.urdf").read_text()
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1))
    return path


def test_clean_urdf_exits_0_with_table() -> None:
    r = armcli("check", "urdf/my_robot.urdf")
    assert r.returncode == 0, r.stderr
    assert "0 error(s), 0 warning(s) in 1 file(s)" in r.stdout
    assert r.stderr == ""


def test_spec_json_schema_and_fk() -> None:
    r = armcli("check", "specs/my_robot.yaml", "--format", "json")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert doc["schema"] == "armcli.check/1" and doc["exit_code"] == 0
    files = {f["file"]: f for f in doc["files"]}
    robot = files["specs/my_robot.yaml#my_robot.urdf"]
    home = next(p for p in robot["summary"]["poses"] if p["name"] == "home")
    assert home["xyz"] == pytest.approx(HAND_TIP_HOME, abs=FK_ATOL)
    assert {f["rule"] for f in robot["findings"]} == set()  # the example's gains: both loops
    st = robot["summary"]["stability"]
    assert st["explicit"]["stable"] is True and st["implicit"]["stable"] is True
    assert st["explicit"]["loop"].startswith("explicit torque loop")
    assert st["lambda_max"] == pytest.approx(554.0, rel=1e-3)
    assert set(doc["counts"]) == {"error", "warning"}


def test_course_gains_warn_for_the_explicit_loop(tmp_path: Path) -> None:
    """The issue: Kp 50, Kd 5 at 1 ms is stable in armcli simulate, not in an explicit loop.

    Nor in the ros2_control controller holding its effort for 1 ms (the spec's 1000 Hz):
    one joint's (Kd + D) T lambda_max = 5.1 x 0.001 x 554 = 2.8 > 2 (tests/analysis/test_zoh.py).
    """
    r = armcli("check", course_gains_spec(tmp_path), "--format", "json")
    assert r.returncode == 1, r.stderr  # the controller's divergence is an error
    robot = next(f for f in json.loads(r.stdout)["files"] if f["file"].endswith("my_robot.urdf"))
    found = {f["rule"]: f["severity"] for f in robot["findings"]}
    assert found == {"pd-explicit-unstable": "warning", "ros-controller-unstable": "error"}
    st = robot["summary"]["stability"]
    assert st["explicit"]["stable"] is False and st["implicit"]["stable"] is True
    assert st["explicit"]["suggestion"]["dt"] == 0.00063  # 0.9 x 0.705 ms, rounded down
    assert robot["summary"]["rate"]["stable"] is False


def test_strict_turns_warnings_into_exit_1_and_ignore_silences(tmp_path: Path) -> None:
    spec = course_gains_spec(tmp_path)
    r = armcli("check", spec.name, "--strict", "--format", "github", cwd=tmp_path)
    assert r.returncode == 1
    gains_line = spec.read_text().splitlines().index("  gains:") + 1
    assert r.stdout.startswith(
        f"::error file=my_robot.yaml,line={gains_line},title=armcli pd-explicit-unstable::"
        "control.gains (my_robot.urdf:"
    )
    assert "error finding(s)" in r.stderr
    ignored = ["--ignore", "pd-explicit-unstable", "--ignore", "ros-controller-unstable"]
    r = armcli("check", spec.name, "--strict", *ignored, cwd=tmp_path)
    assert r.returncode == 0, r.stdout


def test_error_finding_exits_1_with_github_annotation(tmp_path: Path) -> None:
    path = broken_copy(tmp_path, '<mass value="0.3"/>', '<mass value="-0.3"/>')
    r = armcli("check", path, "--format", "github")
    assert r.returncode == 1
    line = r.stdout.splitlines()[0]
    mass_line = path.read_text().splitlines().index('      <mass value="-0.3"/>') + 1
    assert line.startswith(f"::error file={path},line={mass_line},title=armcli mass-nonpositive::")


def test_foreign_xacro_code_is_refused_without_running_it(tmp_path: Path) -> None:
    marker = tmp_path / "pwned"
    evil = tmp_path / "evil.urdf.xacro"
    evil.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        f"<xacro:property name=\"x\" value=\"${{__import__('os').system('touch {marker}')}}\"/>"
        '<link name="${x}"/></robot>'
    )
    r = armcli("check", evil)
    assert r.returncode == 2
    assert r.stdout == ""
    assert "name '__import__' is not allowed" in r.stderr and "--trust-xacro" in r.stderr
    assert not marker.exists()


def test_trusted_xacro_is_expanded_in_a_sandbox() -> None:
    r = armcli("check", "--trust-xacro", FIXTURES / "course_macros.urdf.xacro", "--format", "json")
    assert r.returncode == 1, r.stderr  # the 4x inertias are impossible for their shapes
    (f,) = json.loads(r.stdout)["files"]
    assert {x["rule"] for x in f["findings"]} == {"inertia-geometry", "inertia-exceeds-geometry"}


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (None, "URDF file not found"),
        ("<robot><link", "not well-formed"),
        ('<!DOCTYPE r [<!ENTITY a "b">]><robot name="r"/>', "DOCTYPE"),
    ],
)
def test_unusable_input_exits_2(tmp_path: Path, content: str | None, message: str) -> None:
    path = tmp_path / "bad.urdf"
    if content is not None:
        path.write_text(content)
    r = armcli("check", path)
    assert r.returncode == 2
    assert message in r.stderr and str(path) in r.stderr
    assert len(r.stderr.splitlines()) == 1


def test_good_and_bad_inputs_report_the_good_and_exit_2(tmp_path: Path) -> None:
    r = armcli("check", "urdf/my_robot.urdf", tmp_path / "missing.urdf", "--format", "json")
    assert r.returncode == 2
    doc = json.loads(r.stdout)
    good, bad = doc["files"]
    assert good["file"] == "urdf/my_robot.urdf" and "error" not in good
    assert bad["file"] == str(tmp_path / "missing.urdf") and "not found" in bad["error"]
    assert [f["rule"] for f in bad["findings"]] == ["input-unusable"]
    assert doc["exit_code"] == 2  # a file named on the command line is unusable


def test_directory_and_spec_option(tmp_path: Path) -> None:
    broken_copy(tmp_path, 'upper="1.5707963267948966"', 'upper="1.5"')
    (tmp_path / "ignored.txt").write_text("not a urdf")
    r = armcli("check", tmp_path, "--spec", "specs/my_robot.yaml", "--format", "json")
    assert r.returncode == 1
    (f,) = json.loads(r.stdout)["files"]
    rules = {x["rule"] for x in f["findings"]}
    assert "spec-limits" in rules
    spec_limits = next(x for x in f["findings"] if x["rule"] == "spec-limits")
    assert spec_limits["values"]["joint"] == "arm_base_forearm_joint"


def test_package_dir_resolves_meshes(tmp_path: Path) -> None:
    # The hand's visual is the only 0.3 m cylinder followed by the orange material.
    tail = (
        '\n      </geometry>\n      <origin rpy="0 0 0" xyz="0 0 0.15"/>'
        '\n      <material name="orange"/>'
    )
    old = '<cylinder length="0.3" radius="0.02"/>' + tail
    new = '<mesh filename="package://my_meshes/hand.stl"/>' + tail
    path = broken_copy(tmp_path, old, new)
    r = armcli("check", path, "--format", "json")
    assert {x["rule"] for x in json.loads(r.stdout)["files"][0]["findings"]} == {"mesh-missing"}
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "hand.stl").write_bytes(b"solid hand\nendsolid hand\n")
    r = armcli("check", path, "--package-dir", f"my_meshes={tmp_path / 'pkg'}")
    assert r.returncode == 0, r.stdout


def test_bad_options_exit_2() -> None:
    r = armcli("check", "urdf/my_robot.urdf", "--ignore", "no-such-rule")
    assert r.returncode == 2 and "unknown rule" in r.stderr
    r = armcli("check", "urdf/my_robot.urdf", "--format", "xml")
    assert r.returncode == 2 and "unknown value 'xml'; valid: table, json, github" in r.stderr


SLOW_XACRO = (
    '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    "<xacro:property name=\"x\" value=\"${len([0 for a in 'x'*30000 for b in 'x'*30000])}\"/>"
    '<link name="${x}"/></robot>'
)
HUGE_XACRO = (
    '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    '<xacro:property name="x" value="${len(\'x\' * 4000000000)}"/>'
    '<link name="${x}"/></robot>'
)


def test_sandbox_stops_runaway_xacro(tmp_path: Path) -> None:
    from armcli.errors import InputError
    from armcli.xacro.sandbox import XACRO_MEMORY_BYTES, expand_untrusted

    slow, huge = tmp_path / "slow.xacro", tmp_path / "huge.xacro"
    slow.write_text(SLOW_XACRO)
    huge.write_text(HUGE_XACRO)
    with pytest.raises(InputError, match="took longer than 1 s"):
        expand_untrusted(slow, timeout=1.0)
    assert XACRO_MEMORY_BYTES < 4_000_000_000  # the string below cannot fit
    with pytest.raises(InputError, match="MemoryError"):
        expand_untrusted(huge)


def test_docs_list_every_rule() -> None:
    from armcli.check.rule_docs import render
    from armcli.check.rules import RULES

    doc = (ROOT / "docs" / "check.md").read_text()
    for rule in RULES.values():
        assert f"| `{rule.id}` | {rule.severity} |" in doc, rule.id
    # The table is the registry's: `python -m armcli.check.rule_docs docs/check.md` regenerates it.
    assert render(doc) == doc


@pytest.mark.parametrize(
    "command", ["build", "check", "simulate", "tune", "ros-package", "view", "render", "tree"]
)
def test_help_lists_choices_and_prints_no_stray_escapes(command: str) -> None:
    """Every --help renders plainly: no rich escape backslash before `[...]`."""
    res = armcli(command, "--help")
    assert res.returncode == 0 and "Usage:" in res.stdout
    assert "\\" not in res.stdout
    if command in ("check", "simulate", "tune"):
        assert "[" in res.stdout and "|" in res.stdout  # a Choice lists its values
