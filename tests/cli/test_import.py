"""`armcli import` end to end: a course student's own xacro files become a spec on which
check, simulate, tune and ros-package run."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from armcli.spec.load import load_spec
from tests.helpers import FIXTURES, ROOT, run_main

STUDENT = FIXTURES / "import" / "course_student" / "urdf" / "my_robot.urdf.xacro"
PICK = ROOT / "specs" / "trajectories" / "pick.yaml"


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    return run_main(args, capsys)


@pytest.fixture
def imported(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    spec = tmp_path / "armcli.yaml"
    code, out, err = run(["import", str(STUDENT), "-o", str(spec)], capsys)
    assert code == 0, err
    assert "robot 'my_robot', 10 links" in out
    assert "arm from 'arm_base_link' on a mobile base" in out
    assert "round trip: `armcli build` gives back the same URDF (checked)" in out
    assert '<gazebo reference="camera_link"> (sensor)' in out  # kept verbatim, and said so
    return spec


def test_import_writes_a_spec_with_start_gains(imported: Path) -> None:
    spec = load_spec(imported)
    assert set(spec.control.gains) == {"arm_base_forearm_joint", "forearm_hand_joint"}
    assert all(g.kp > 0 and g.kd > 0 for g in spec.control.gains.values())
    assert imported.read_text().startswith("# armcli spec imported by `armcli import` from ")


def test_check_reports_the_students_inertia_mistakes(
    imported: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = run(["check", str(imported), "--format", "json"], capsys)
    assert code == 1  # the 2x-dimension and swapped-axis macros are physically impossible
    assert "inertia-exceeds-geometry" in out and "base_link" in out


def test_simulate_and_ros_package_run_on_the_import(
    imported: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run(["simulate", str(imported), "--trajectory", str(PICK)], capsys)
    assert code == 0, err
    assert "end effector hand_link" in out
    pkgs = tmp_path / "ros"
    args = ["ros-package", str(imported), "-o", str(pkgs), "--samples", "200"]
    code, _, err = run(args, capsys)
    assert code == 0, err
    assert (pkgs / "my_robot_description" / "urdf" / "passthrough.xacro").is_file()
    jazzy = ["ros-package", str(imported), "-o", str(tmp_path / "jazzy"), "--samples", "200"]
    code, _, err = run([*jazzy, "--target", "jazzy"], capsys)
    assert code == 0, err  # the start gains let the effort-driven Jazzy target package it


def test_tune_writes_back_into_the_imported_spec(
    imported: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = load_spec(imported).control.gains
    code, _, err = run(["tune", str(imported), "-t", str(PICK), "--trials", "4", "--write"], capsys)
    assert code == 0, err
    assert load_spec(imported).control.gains != before


def test_refuses_to_overwrite_and_bad_arguments(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "armcli.yaml"
    spec.write_text("mine\n")
    code, _, err = run(["import", str(STUDENT), "-o", str(spec)], capsys)
    assert code == 2 and "exists; pass --force" in err and spec.read_text() == "mine\n"
    code, _, err = run(["import", str(STUDENT), "ur_type", "-o", str(tmp_path / "x.yaml")], capsys)
    assert code == 2 and "only xacro arguments NAME:=VALUE may follow" in err, err
    code, _, err = run(
        ["import", str(tmp_path / "missing.urdf"), "-o", str(tmp_path / "y.yaml")], capsys
    )
    assert code == 2 and "missing.urdf" in err
    assert not (tmp_path / "x.yaml").exists() and not (tmp_path / "y.yaml").exists()


def test_strict_exits_1_on_a_listed_difference(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    urdf = tmp_path / "odd.urdf"
    text = (FIXTURES / "import" / "sensor_base.urdf").read_text()
    urdf.write_text(text.replace('<robot name="sensor_base">', '<robot name="sensor base">'))
    code, out, _ = run(["import", str(urdf), "-o", str(tmp_path / "s.yaml"), "--strict"], capsys)
    assert code == 1
    assert "robot name 'sensor base' written as 'sensor_base'" in out
    assert "robot name: sensor base -> sensor_base" in out


def test_init_from_a_urdf(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    shutil.copy(FIXTURES / "import" / "sensor_base.urdf", tmp_path / "robot.urdf")
    code, _, err = run(
        ["init", str(tmp_path / "proj"), "--from", str(tmp_path / "robot.urdf")], capsys
    )
    assert code == 0, err
    assert load_spec(tmp_path / "proj" / "armcli.yaml").name == "sensor_base"


def test_massless_arm_imports_without_start_gains(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    urdf = tmp_path / "frames.urdf"  # no inertia anywhere: no mass matrix to size gains on
    urdf.write_text(
        '<robot name="frames"><link name="a"/><link name="b"/>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    code, out, err = run(["import", str(urdf), "-o", str(tmp_path / "s.yaml")], capsys)
    assert code == 0, err
    assert "gives back the same URDF" in out
    assert load_spec(tmp_path / "s.yaml").control.gains == {}
