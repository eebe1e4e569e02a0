"""Every spec under specs/ end to end: builds, loads, checks clean, simulates, packages.

Modelled on mujoco_menagerie's model test: a new spec dropped into specs/ is
exercised by the whole tool chain without writing a test for it.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from armcli.check.rules import ERROR, CheckOptions
from armcli.check.run import check_urdf
from armcli.cli import main
from armcli.compiler.expand import build
from armcli.spec.model import RobotSpec
from armcli.urdf.read import read_urdf
from tests.helpers import ROOT

SPECS = sorted((ROOT / "specs").glob("*.yaml"))
# Gravity-compensated PD holds a pose to within friction / Kp (<= 0.05 / 15 here) [rad].
HOLD_TOL = 0.01
SIM_SECONDS = 1.5


@pytest.fixture(scope="module", params=SPECS, ids=[p.stem for p in SPECS])
def built(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory):  # type: ignore[no-untyped-def]
    out = tmp_path_factory.mktemp(request.param.stem)
    result = build(request.param, out)
    return request.param, result.spec, out


def test_specs_exist() -> None:
    assert len(SPECS) >= 2


def test_builds_and_loads(built: tuple[Path, RobotSpec, Path]) -> None:
    _, spec, out = built
    model = pin.buildModelFromUrdf(str(out / "standalone_arm.urdf"))
    assert [model.names[i] for i in range(1, model.njoints)] == spec.movable_arm_joints()
    arm_mass = sum(link.mass or 0.0 for link in spec.arm.links.values())
    assert sum(i.mass for i in model.inertias) == pytest.approx(arm_mass, rel=1e-12)


def test_checks_without_errors(built: tuple[Path, RobotSpec, Path]) -> None:
    _, spec, out = built
    for urdf in sorted(out.glob("*.urdf")):
        result = check_urdf(read_urdf(urdf), CheckOptions(spec=spec))
        errors = [f for f in result.findings if f.severity == ERROR]
        assert errors == [], errors


def test_holds_a_named_pose(
    built: tuple[Path, RobotSpec, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path, spec, _ = built
    joints = spec.movable_arm_joints()
    pose_name = next(n for n in spec.poses if n != "home")
    target = [spec.pose(pose_name)[j] for j in joints]
    message = (
        f"{{joint_names: [{', '.join(joints)}], "
        f"points: [{{positions: [{', '.join(repr(x) for x in target)}], time_from_start: 1.0}}]}}"
    )
    states = tmp_path / "states.csv"
    monkeypatch.chdir(path.parents[1])
    with pytest.raises(SystemExit) as info:
        main(
            [
                "simulate",
                str(path),
                "--message",
                message,
                "--gravity-comp",
                "--duration",
                str(SIM_SECONDS),
                "--output",
                str(states),
            ]
        )
    assert info.value.code in (0, None)
    with states.open() as fh:
        rows = list(csv.DictReader(fh))
    assert float(rows[-1]["time"]) == pytest.approx(SIM_SECONDS)
    final = np.array([float(rows[-1][f"{j}.position"]) for j in joints])
    assert np.all(np.abs(final - target) < HOLD_TOL), (final, target)
    assert all(math.isfinite(float(v)) for row in rows for v in row.values())


def test_ros_package(built: tuple[Path, RobotSpec, Path], tmp_path: Path) -> None:
    path, spec, _ = built
    with pytest.raises(SystemExit) as info:
        main(["ros-package", str(path), "-o", str(tmp_path), "--samples", "200"])
    assert info.value.code in (0, None)
    srdf = tmp_path / f"{spec.name}_moveit_config" / "config" / f"{spec.name}.srdf"
    assert srdf.is_file()


def test_ros_package_jazzy(built: tuple[Path, RobotSpec, Path], tmp_path: Path) -> None:
    path, spec, _ = built
    with pytest.raises(SystemExit) as info:
        main(
            ["ros-package", str(path), "-o", str(tmp_path), "--samples", "200", "--target", "jazzy"]
        )
    assert info.value.code in (0, None)
    bringup = tmp_path / f"{spec.name}_bringup"
    assert (bringup / "config" / f"{spec.name}_controllers.yaml").is_file()
    assert (bringup / "launch" / f"{spec.name}_gz.launch.py").is_file()
    assert (
        tmp_path / f"{spec.name}_description" / "urdf" / "standalone_arm_gz.urdf.xacro"
    ).is_file()


def test_export_mjcf_loads_in_mujoco(built: tuple[Path, RobotSpec, Path], tmp_path: Path) -> None:
    mujoco = pytest.importorskip("mujoco")
    path, spec, _ = built
    out = tmp_path / "robot.xml"
    with pytest.raises(SystemExit) as info:
        main(["export", "mjcf", str(path), "-o", str(out)])
    assert info.value.code in (0, None)
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "scene.xml"))
    assert m.nu == len(spec.control.gains) and m.nkey == len({"home", *spec.poses})


def test_tune(built: tuple[Path, RobotSpec, Path], tmp_path: Path) -> None:
    path, spec, _ = built
    out = tmp_path / "tune.json"
    with pytest.raises(SystemExit) as info:
        main(
            ["tune", str(path), "--trials", "3", "--batch", "3", "--settle", "0.5", "-o", str(out)]
        )
    assert info.value.code in (0, None)
    doc = json.loads(out.read_text(encoding="utf-8"))
    assert doc["problem"]["joints"] == spec.movable_arm_joints()
    assert doc["results"]["tuned"]["feasible"]


def test_drives_on_its_wheels(built: tuple[Path, RobotSpec, Path], tmp_path: Path) -> None:
    """A spec with a diff-drive plugin drives 2 s forward in MuJoCo and stays upright."""
    pytest.importorskip("mujoco")
    path, spec, _ = built
    if spec.mobile_base is None or spec.mobile_base.diff_drive is None:
        pytest.skip("no diff-drive plugin to drive")
    cmd = tmp_path / "forward.yaml"
    cmd.write_text("commands:\n  - {linear: {x: 0.2}, time_from_start: 0.2}\n")
    states = tmp_path / "drive.csv"
    with pytest.raises(SystemExit) as info:
        main(["simulate", str(path), "--cmd-vel", str(cmd), "--duration", "2", "-o", str(states)])
    assert info.value.code in (0, None)
    with states.open() as fh:
        last = list(csv.DictReader(fh))[-1]
    # 0.2 m/s from 0.2 s to 2 s, less what the plugin's ramp loses at the start: v² / 2a
    accel = spec.mobile_base.diff_drive.max_wheel_acceleration
    expected = 0.2 * (2.0 - 0.2) - 0.2**2 / (2 * accel)  # 0.34 m for the course robot
    assert float(last["odom.x"]) == pytest.approx(expected, rel=0.1)
    assert float(last["base.x"]) == pytest.approx(expected, rel=0.1)
