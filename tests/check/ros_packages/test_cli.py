"""`armcli check DIR` on packages through the CLI: every output format, bad input, no code run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.check.ros_packages.test_rule_fixtures import CONTROLLERS, _no_integral
from tests.check.ros_packages.workspaces import copy
from tests.check.test_sarif import validate
from tests.helpers import run_main

LAUNCH_OK = """from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([Node(package="rviz2", executable="rviz2")])
"""


@pytest.fixture
def sagging(jazzy_pkgs: Path, tmp_path: Path) -> Path:
    """The generated jazzy packages with the course's old gains (p 50, i 0)."""
    root = copy(jazzy_pkgs, tmp_path / "ws")
    _no_integral(root)
    return root


def test_warning_in_every_format_and_strict(
    sagging: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run_main(["check", sagging, "--format", "json"], capsys)
    assert code == 0 and "3 ROS package(s)" in err and "distro jazzy" in err
    doc = json.loads(out)
    sag = [f for file in doc["files"] for f in file["findings"] if f["rule"] == "ros-start-sag"]
    assert {f["values"]["pose"] for f in sag} == {"reach", "folded"}
    assert all(f["file"].endswith(CONTROLLERS) and f["line"] and f["fix"]["p"] for f in sag)
    code, out, _ = run_main(["check", sagging, "--format", "github"], capsys)
    assert out.count("::warning file=") == 2 and "title=armcli ros-start-sag" in out
    code, out, _ = run_main(["check", sagging, "--format", "sarif", "--strict"], capsys)
    assert code == 1
    sarif = json.loads(out)
    validate(sarif)
    assert {r["level"] for r in sarif["runs"][0]["results"]} == {"error"}
    code, out, _ = run_main(["check", sagging, "--ignore", "ros-start-sag", "--strict"], capsys)
    assert code == 0 and "ros-start-sag" not in out


def test_distro_option(sagging: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_main(["check", sagging, "--distro", "kilted", "--format", "json"], capsys)
    assert code == 0 and "distro kilted (--distro)" in err
    code, _, err = run_main(["check", sagging, "--distro", "rolling"], capsys)
    assert code == 2 and "--distro" in err and "humble, jazzy, kilted, lyrical" in err


def test_bad_files_are_findings_with_file_and_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = tmp_path / "src" / "bringup"
    (pkg / "launch").mkdir(parents=True)
    (pkg / "config").mkdir()
    (pkg / "package.xml").write_text(
        "<package format='3'><name>bringup</name><exec_depend>rviz2</exec_depend></package>\n"
    )
    (pkg / "launch" / "broken.launch.py").write_text(
        "def generate_launch_description():\n    return LaunchDescription([\n"
    )
    (pkg / "launch" / "ok.launch.py").write_text(
        LAUNCH_OK.replace(
            'executable="rviz2")',
            'executable="rviz2", parameters=["' + str(pkg / "config" / "p.yaml") + '"])',
        )
    )
    (pkg / "config" / "p.yaml").write_text("rviz2:\n  ros__parameters:\n\tuse_sim_time: true\n")
    other = tmp_path / "src" / "other"
    other.mkdir()
    (other / "package.xml").write_text("<package format='3'>\n<name>other</name>\n<package>\n")
    code, out, err = run_main(["check", tmp_path, "--format", "json"], capsys)
    assert code == 1 and "Traceback" not in err
    found = [f for file in json.loads(out)["files"] for f in file["findings"]]
    where = {(Path(f["file"]).name, f["line"]) for f in found if f["rule"] == "input-unusable"}
    # the launch file's open bracket, the YAML's tab, the manifest's unclosed element
    assert where == {("broken.launch.py", 2), ("p.yaml", 3), ("package.xml", 4)}


def test_nothing_in_any_file_is_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Launch files (Python, XML, YAML) whose every line would create a file if launched."""
    planted = tmp_path / "planted"
    pkg = tmp_path / "pkg"
    (pkg / "launch").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='3'><name>pkg</name></package>\n")
    (pkg / "launch" / "evil.launch.py").write_text(
        f"import os\nos.system('touch {planted}.py')\nopen('{planted}.open', 'w')\n"
        "from launch import LaunchDescription\n"
        "def generate_launch_description():\n"
        f"    os.system('touch {planted}.fn')\n"
        "    return LaunchDescription([])\n"
    )
    (pkg / "launch" / "evil.launch.xml").write_text(
        "<launch>\n"
        f"  <let name='x' value=\"$(command 'touch {planted}.xml')\"/>\n"
        f"  <executable cmd='touch {planted}.exe'/>\n"
        "  <let name='y' value=\"$(eval '__import__(\\'os\\').system("
        f"\\'touch {planted}.e\\')')\"/>\n"
        "</launch>\n"
    )
    (pkg / "launch" / "evil.launch.yaml").write_text(
        f"launch:\n- executable: {{cmd: touch {planted}.yaml}}\n"
    )
    code, _, err = run_main(["check", tmp_path], capsys)
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pkg"]
