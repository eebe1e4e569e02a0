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
from lxml import etree

from armcli.check.options import CheckOptions
from armcli.check.rules import ERROR
from armcli.check.run import check_urdf
from armcli.cli import main
from armcli.compiler.expand import build
from armcli.spec.load import load_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.read import read_urdf
from tests.helpers import FIXTURES, ROOT
from tests.meshes import house_triangles, prism_triangles, write_stl

SPECS = sorted((ROOT / "specs").glob("*.yaml"))
# Gravity-compensated PD holds a pose to within friction / Kp (<= 0.05 / 15 here) [rad].
HOLD_TOL = 0.01
SIM_SECONDS = 1.5


@pytest.fixture(scope="module", params=SPECS, ids=[p.stem for p in SPECS])
def built(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory):
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
    assert _package_findings(tmp_path) == []


def _package_findings(root: Path) -> list[str]:
    """The package rules' findings (and unreadable files) of `check DIR` on ros-package's output."""
    from armcli.check.ros_packages.run import check_packages

    found = [f for r in check_packages(root, CheckOptions()).results for f in r.findings]
    return [f"{f.rule}: {f.message}" for f in found
            if f.rule.startswith("ros-") or f.rule == "input-unusable"]  # fmt: skip


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
    assert _package_findings(tmp_path) == []


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


# -- A feature-rich spec through the same chain ---------------------------------------------
# specs/ holds plain arms; rich_arm (tests/fixtures/spec) adds what they lack: a part placed
# twice, a mimic joint, meshes (written by tests/meshes.py), sensors and passthrough XML.
RICH = FIXTURES / "spec" / "rich_arm.yaml"
# The finger needs a gain to be driven; the fixture's other readers keep it without one.
FINGER_GAIN = "    left_finger_joint: {kp: 200, kd: 5}\n"
RICH_TARGET = {"shoulder_lift_joint": 0.5, "elbow_joint": -0.8, "left_finger_joint": 0.02}
# What `check` finds in rich_arm, by design of the fixture: a 4 kg root link (KDL ignores
# it), Kp = 400 with Kd = 20 too stiff for an explicit loop at 1 ms, and lidars 0.1 m off
# the axis of base_link's collision cylinder (r 0.08): the rays heading back start, range_min
# out, inside it: the lidar sees the base (check/sensors.py); nothing else.
RICH_FINDINGS = {("root-inertia", "warning"), ("pd-explicit-unstable", "warning"),
                 ("sensor-sees-robot", "warning")}  # fmt: skip


def _run(argv: list[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code in (0, None), argv


@pytest.fixture(scope="module")
def rich(tmp_path_factory: pytest.TempPathFactory) -> Path:
    project = tmp_path_factory.mktemp("rich")
    text = RICH.read_text(encoding="utf-8")
    anchor = "    wrist_3_joint: {kp: 20, kd: 1}\n"
    assert anchor in text
    (project / "armcli.yaml").write_text(text.replace(anchor, anchor + FINGER_GAIN))
    write_stl(project / "meshes" / "base.stl", prism_triangles(0.08, 0.1, 32))
    write_stl(project / "meshes" / "link.stl", house_triangles())
    return project / "armcli.yaml"


def test_rich_spec_builds_urdfs_pinocchio_and_its_meshes_agree_on(
    rich: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = rich.parent / "urdf"
    _run(["build", str(rich), "-o", str(out)])
    assert capsys.readouterr().err == ""  # no warning: the built URDFs are what check reads
    urdf = out / "standalone_arm.urdf"
    root = etree.parse(str(urdf)).getroot()
    for mesh in root.iter("mesh"):  # written relative to the URDF, and there
        assert (out / str(mesh.get("filename"))).is_file()
    model = pin.buildModelFromUrdf(str(urdf))
    # 6 arm joints and one finger part placed twice
    assert model.nv == 8 and model.existFrame("left_finger_link")
    assert model.existFrame("right_finger_link")
    follower = root.find("joint[@name='right_finger_joint']/mimic")
    assert follower is not None and follower.get("joint") == "left_finger_joint"
    sensors = {s.get("name") for s in root.iter("sensor")}
    assert sensors >= {"wrist_camera", "wrist_depth", "base_scan", "base_cloud", "base_imu"}


def test_rich_spec_check_finds_what_the_fixture_holds(
    rich: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    capsys.readouterr()
    _run(["check", str(rich), "--format", "json"])  # warnings only: exit 0
    doc = json.loads(capsys.readouterr().out)
    found = {(f["rule"], f["severity"]) for file in doc["files"] for f in file["findings"]}
    assert found == RICH_FINDINGS


def test_rich_spec_simulates_within_limits_with_its_mimic_following(
    rich: Path, tmp_path: Path
) -> None:
    spec = load_spec(rich)
    states = tmp_path / "states.csv"
    names = ", ".join(RICH_TARGET)
    values = ", ".join(repr(x) for x in RICH_TARGET.values())
    message = (
        f"{{joint_names: [{names}], points: [{{positions: [{values}], time_from_start: 1.0}}]}}"
    )
    argv = ["simulate", str(rich), "--message", message, "--gravity-comp"]
    _run([*argv, "--duration", str(SIM_SECONDS), "--output", str(states)])
    with states.open() as fh:
        rows = list(csv.DictReader(fh))
    assert float(rows[-1]["time"]) == pytest.approx(SIM_SECONDS)
    joints = spec.all_joints()  # the arm's own and the placed parts' joints
    for row in rows:
        assert all(math.isfinite(float(v)) for v in row.values())
        for name in spec.movable_arm_joints():
            q, limit = float(row[f"{name}.position"]), joints[name].limit
            if limit is not None and limit.lower is not None and limit.upper is not None:
                assert limit.lower - HOLD_TOL <= q <= limit.upper + HOLD_TOL, (name, q)
        # mimic (multiplier 1, offset 0): the follower is driven to its leader's reference
        assert row["right_finger_joint.reference"] == row["left_finger_joint.reference"]
    follower = {"right_finger_joint": RICH_TARGET["left_finger_joint"]}
    for name, target in {**RICH_TARGET, **follower}.items():
        assert abs(float(rows[-1][f"{name}.position"]) - target) < HOLD_TOL, name


def test_rich_spec_ros_package_parses_and_carries_its_meshes(rich: Path, tmp_path: Path) -> None:
    _run(["ros-package", str(rich), "-o", str(tmp_path), "--samples", "200"])
    desc = tmp_path / "rich_arm_description"
    for name in ("base.stl", "link.stl"):  # copied byte for byte into the package
        assert (desc / "meshes" / name).read_bytes() == (rich.parent / "meshes" / name).read_bytes()
    assert etree.parse(str(desc / "package.xml")).getroot().findtext("name") == desc.name
    srdf = etree.parse(str(tmp_path / "rich_arm_moveit_config" / "config" / "rich_arm.srdf"))
    pairs = srdf.getroot().findall("disable_collisions")
    model = pin.buildModelFromUrdf(str(_standalone(rich, tmp_path)))
    for pair in pairs:  # every pair names links of the robot
        assert model.existFrame(str(pair.get("link1"))) and model.existFrame(str(pair.get("link2")))


def _standalone(rich: Path, tmp_path: Path) -> Path:
    out = tmp_path / "built"
    build(rich, out)
    return out / "standalone_arm.urdf"


def test_rich_spec_exports_mjcf_that_mujoco_loads_with_the_spec_mass(
    rich: Path, tmp_path: Path
) -> None:
    mujoco = pytest.importorskip("mujoco")
    _run(["export", "mjcf", str(rich), "-o", str(tmp_path / "robot.xml")])
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "scene.xml"))
    robot = pin.buildModelFromUrdf(str(_standalone(rich, tmp_path)))
    # a second engine's mass: Pinocchio's, from the URDF the same spec builds
    assert sum(m.body_mass) == pytest.approx(sum(i.mass for i in robot.inertias), rel=1e-9)
    assert m.njnt == robot.nv == 8
    assert m.neq == 1  # the mimic finger: MuJoCo's joint equality, not an actuator
