"""`ros-package --target jazzy`, verified without ROS.

References: package.xml against catkin_pkg's validator; launch files against their
own syntax trees (every package they import, launch or look up must be declared);
YAML against the expanded URDF's joints and the spec; the URDF with its
`<ros2_control>` block against urdfdom's `check_urdf`, `armcli check` and Pinocchio
(its dynamics must equal the course URDF's: ros2_control adds no bodies). Golden
files in tests/ros/golden/jazzy/ were generated once and reviewed; the semantic tests
below say what they must mean. The course target is compared with checksums
of the pre-jazzy writer's output (tests/ros/golden/humble_classic.sha256).
"""

from __future__ import annotations

import ast
import hashlib
import shutil
import subprocess
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest
import yaml
from catkin_pkg.package import parse_package_string
from lxml import etree

from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.compiler.xacro_writer import WORLD_JOINT
from armcli.errors import InputError
from armcli.ros import jazzy
from armcli.ros.holding import integral_terms
from armcli.ros.packages import RosPackages, ros_packages
from armcli.spec.load import load_spec, loads_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.read import parse_urdf
from armcli.urdf.source import spec_urdfs
from tests.helpers import ROOT, run_cli

GOLDEN = ROOT / "tests" / "ros" / "golden"
SAMPLES = 300  # as test_ros_package.py
LABEL = "specs/my_robot.yaml"
DESC, BRINGUP, MOVEIT = "my_robot_description", "my_robot_bringup", "my_robot_moveit_config"
GOLDEN_FILES = [
    f"{BRINGUP}/README.md",
    f"{BRINGUP}/config/my_robot_bridge.yaml",
    f"{BRINGUP}/config/my_robot_controllers.yaml",
    f"{BRINGUP}/launch/my_robot_gz.launch.py",
    f"{BRINGUP}/package.xml",
    f"{DESC}/urdf/my_robot_gz.urdf.xacro",
    f"{DESC}/urdf/standalone_arm_gz.urdf.xacro",
    f"{MOVEIT}/config/moveit_controllers.yaml",
    f"{MOVEIT}/launch/gz_move_group.launch.py",
    f"{MOVEIT}/package.xml",
]
CONTROLLERS = f"{BRINGUP}/config/my_robot_controllers.yaml"
# Python modules a launch file may import, by the ROS package that provides them.
MODULE_PACKAGE = {"launch": "launch", "launch_ros": "launch_ros"}
RIGID_TOL = 1e-12  # [kg·m²] same URDF bodies -> same mass matrix up to rounding


@pytest.fixture(scope="module")
def spec() -> RobotSpec:
    return load_spec(ROOT / LABEL)


@pytest.fixture(scope="module")
def pkgs(spec: RobotSpec) -> RosPackages:
    return ros_packages(spec, label=LABEL, samples=SAMPLES, seed=0, target="jazzy")


@pytest.fixture(scope="module")
def files(pkgs: RosPackages) -> Mapping[str, bytes]:
    return pkgs.files


def expand(files: Mapping[str, bytes], top: str, tmp: Path, mock: bool = False) -> bytes:
    """The description's xacro expanded by the real xacro, as the launch file runs it."""
    import xacro

    urdf_dir = tmp / DESC / "urdf"
    for path, data in files.items():
        if path.startswith(f"{DESC}/urdf/"):
            (urdf_dir / Path(path).name).parent.mkdir(parents=True, exist_ok=True)
            (urdf_dir / Path(path).name).write_bytes(data)
    controllers = tmp / "controllers.yaml"
    mappings = {"controllers_file": str(controllers), "use_mock_hardware": str(mock).lower()}
    doc = xacro.process_file(str(urdf_dir / top), mappings=mappings)
    return bytes(doc.toprettyxml(indent="  ", encoding="utf-8"))


def _exec_depends(files: Mapping[str, bytes], pkg: str) -> set[str]:
    manifest = parse_package_string(files[f"{pkg}/package.xml"].decode())
    return {d.name for d in manifest.exec_depends}


# -- golden files and determinism ---------------------------------------------------------


@pytest.mark.parametrize("path", GOLDEN_FILES)
def test_golden_files(files: Mapping[str, bytes], path: str) -> None:
    assert files[path] == (GOLDEN / "jazzy" / path).read_bytes()


def test_regeneration_is_byte_identical(spec: RobotSpec, pkgs: RosPackages) -> None:
    again = ros_packages(spec, label=LABEL, samples=SAMPLES, seed=0, target="jazzy")
    assert again.files == pkgs.files


def test_default_target_is_the_course_output_unchanged(spec: RobotSpec) -> None:
    # reference: sha256 of every file the pre-jazzy writer (main at dedc9ce) produced
    # for this spec, label, sample count and seed; since then the standalone arm has a
    # massless `world` root (issue 23) and the `folded` pose stops at 1.5 rad, off the base
    # (issue 31: the SRDF's group state, and base_link/forearm_link never collide), and
    # joint_limits.yaml has acceleration limits (issue 29: 1.0 rad/s², `plan`'s default)
    want = dict(
        line.split("  ")[::-1]
        for line in (GOLDEN / "humble_classic.sha256").read_text().splitlines()
    )
    got = ros_packages(spec, label=LABEL, samples=SAMPLES, seed=0).files
    assert {p: hashlib.sha256(d).hexdigest() for p, d in got.items()} == want


# -- package.xml ----------------------------------------------------------------------------


def test_package_xml_is_valid_and_depends_on_what_runs(files: Mapping[str, bytes]) -> None:
    for pkg in (DESC, BRINGUP, MOVEIT):
        warnings: list[str] = []
        manifest = parse_package_string(files[f"{pkg}/package.xml"].decode(), warnings=warnings)
        manifest.validate(warnings=warnings)
        assert warnings == [] and manifest.name == pkg and manifest.package_format == 3
    assert set(jazzy.BRINGUP_DEPENDS) | {DESC} == _exec_depends(files, BRINGUP)
    assert {"ros_gz_sim", "ros_gz_bridge", "gz_ros2_control"} <= _exec_depends(files, BRINGUP)


# -- launch files -----------------------------------------------------------------------------


def _launch_packages(source: bytes) -> set[str]:
    """Every ROS package a launch file uses: imports, Node(package=), share lookups."""
    tree = ast.parse(source)
    compile(tree, "launch", "exec")
    consts = {
        t.id: n.value.value
        for n in tree.body
        if isinstance(n, ast.Assign) and isinstance(n.value, ast.Constant)
        for t in n.targets
        if isinstance(t, ast.Name)
    }

    def value(node: ast.expr) -> object:
        if isinstance(node, ast.Constant):
            return node.value
        return consts.get(node.id) if isinstance(node, ast.Name) else None

    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            top = node.module.split(".")[0]
            out.add(MODULE_PACKAGE.get(top, top))
        elif isinstance(node, ast.Import):
            out |= {a.name.split(".")[0] for a in node.names if a.name != "os"}
        elif isinstance(node, ast.Call):
            name = getattr(node.func, "id", getattr(node.func, "attr", ""))
            if name == "get_package_share_directory":
                out.add(str(value(node.args[0])))
            out |= {str(value(k.value)) for k in node.keywords if k.arg == "package"}
    return out - {"os"}


@pytest.mark.parametrize(
    ("pkg", "launch"),
    [(BRINGUP, "launch/my_robot_gz.launch.py"), (MOVEIT, "launch/gz_move_group.launch.py")],
)
def test_launch_names_only_declared_packages(
    files: Mapping[str, bytes], pkg: str, launch: str
) -> None:
    used = _launch_packages(files[f"{pkg}/{launch}"])
    assert used, "the AST walk found nothing: it is broken"
    assert used <= _exec_depends(files, pkg) | {pkg}


def test_bringup_launch_chains_spawners_after_the_spawn(files: Mapping[str, bytes]) -> None:
    tree = ast.parse(files[f"{BRINGUP}/launch/my_robot_gz.launch.py"])
    handlers = [
        n
        for n in ast.walk(tree)
        if isinstance(n, ast.Call) and getattr(n.func, "id", "") == "OnProcessExit"
    ]
    chain = [
        ({k.arg: getattr(k.value, "id", None) for k in h.keywords}) for h in handlers
    ]  # target_action -> first of on_exit
    assert [c["target_action"] for c in chain] == ["spawn", "joint_state_broadcaster"]
    text = files[f"{BRINGUP}/launch/my_robot_gz.launch.py"].decode()
    for needle in (
        '"gz_sim.launch.py"',
        '"-r " + WORLD',
        'WORLD = "empty.sdf"',
        '"-topic", "robot_description"',
        '"config_file": os.path.join(config, BRIDGE)',
        'BRIDGE = "my_robot_bridge.yaml"',
        'AppendEnvironmentVariable("GZ_SIM_RESOURCE_PATH"',
        'executable="create"',
        '" controllers_file:="',
    ):
        assert needle in text, needle


# -- YAML against the URDF and the spec ------------------------------------------------------


def test_every_yaml_parses_and_names_only_urdf_joints(
    files: Mapping[str, bytes], tmp_path: Path
) -> None:
    urdf = parse_urdf(expand(files, "my_robot_gz.urdf.xacro", tmp_path), "jazzy.urdf")
    joints = {j.name for j in urdf.joints}
    docs = {p: yaml.safe_load(d) for p, d in files.items() if p.endswith((".yaml", ".rviz"))}
    assert len(docs) >= 8
    ctl = docs[CONTROLLERS]["arm_controller"]["ros__parameters"]
    named = set(ctl["joints"]) | set(ctl["gains"]) | (set(ctl["constraints"]) - {
        "stopped_velocity_tolerance", "goal_time"})  # fmt: skip
    moveit = docs[f"{MOVEIT}/config/moveit_controllers.yaml"]["moveit_simple_controller_manager"]
    named |= set(moveit["arm_controller"]["joints"])
    assert named and named <= joints


def test_controllers_carry_the_spec_gains_rate_and_tolerances(
    files: Mapping[str, bytes], spec: RobotSpec
) -> None:
    doc = yaml.safe_load(files[CONTROLLERS])
    cm = doc["controller_manager"]["ros__parameters"]
    assert cm["update_rate"] == spec.control.controller_update_rate
    assert cm["arm_controller"]["type"] == "joint_trajectory_controller/JointTrajectoryController"
    assert cm["joint_state_broadcaster"]["type"] == "joint_state_broadcaster/JointStateBroadcaster"
    arm = doc["arm_controller"]["ros__parameters"]
    assert arm["command_interfaces"] == ["effort"]
    assert arm["joints"] == spec.movable_arm_joints()
    # The spec's PD sags 0.028 rad at `reach` (> MoveIt's 0.01): the generator adds the
    # integral term of ros/holding.py (tests/ros/test_holding.py), clamped at the effort limit
    holding = integral_terms(spec, spec_urdfs(spec)[f"{spec.name}.urdf"])
    assert set(holding) == set(spec.control.gains)
    for j, g in spec.control.gains.items():
        # JTC effort law: ff_velocity_scale * v_ref + p e + d e' + i ∫e == the spec's PD + I
        extra = holding[j]
        want = {"p": g.kp, "d": g.kd, "i": extra.i, "i_clamp": 100.0, "ff_velocity_scale": 0.0}
        assert extra.i > 0
        assert arm["gains"][j] == want
        assert arm["constraints"][j] == {
            "trajectory": spec.control.tolerances.trajectory,
            "goal": spec.control.tolerances.goal,
        }
    moveit = yaml.safe_load(files[f"{MOVEIT}/config/moveit_controllers.yaml"])
    entry = moveit["moveit_simple_controller_manager"]["arm_controller"]
    assert (entry["type"], entry["action_ns"]) == (
        "FollowJointTrajectory",
        "follow_joint_trajectory",
    )


def test_integral_gain_gets_the_effort_limit_as_clamp(default_spec_path: Path) -> None:
    text = default_spec_path.read_text().replace("{kp: 50, kd: 1.5}", "{kp: 50, kd: 1.5, ki: 2}")
    doc = jazzy.controllers(loads_spec(text))
    assert doc["arm_controller"]["ros__parameters"]["gains"]["forearm_hand_joint"]["i_clamp"] == 100


def test_missing_gains_are_refused_with_the_field(default_spec_path: Path) -> None:
    text = default_spec_path.read_text().replace("    forearm_hand_joint: {kp: 50, kd: 1.5}\n", "")
    with pytest.raises(InputError, match="forearm_hand_joint") as exc:
        ros_packages(loads_spec(text), samples=10, target="jazzy", source="x.yaml")
    assert exc.value.field == "control.gains"


# -- the URDF with <ros2_control> ------------------------------------------------------------


@pytest.mark.parametrize("mock", [False, True], ids=["gz", "mock"])
def test_ros2_control_block(
    files: Mapping[str, bytes], spec: RobotSpec, tmp_path: Path, mock: bool
) -> None:
    root = etree.fromstring(expand(files, "my_robot_gz.urdf.xacro", tmp_path, mock))
    rc = root.find("ros2_control")
    assert rc is not None
    assert rc.findtext("hardware/plugin") == (jazzy.MOCK_SYSTEM if mock else jazzy.GZ_SYSTEM)
    by_name = {j.get("name"): j for j in rc.findall("joint")}
    for name in spec.movable_arm_joints():
        j = by_name[name]
        assert [c.get("name") for c in j.findall("command_interface")] == ["effort"]
        assert [s.get("name") for s in j.findall("state_interface")] == [
            "position", "velocity", "effort"]  # fmt: skip
    plugins = root.findall("gazebo/plugin")
    gz = [p for p in plugins if p.get("filename") == jazzy.GZ_PLUGIN_FILE]
    if mock:
        assert plugins == []
    else:
        assert gz[0].get("name") == jazzy.GZ_PLUGIN_NAME
        assert gz[0].findtext("parameters") == str(tmp_path / "controllers.yaml")


def test_jazzy_urdf_passes_check_urdf(files: Mapping[str, bytes], tmp_path: Path) -> None:
    exe = shutil.which("check_urdf")
    if exe is None:
        pytest.skip("check_urdf not installed (make sysdeps installs liburdfdom-tools)")
    for top in ("my_robot_gz.urdf.xacro", "standalone_arm_gz.urdf.xacro"):
        path = tmp_path / f"{top}.urdf"
        path.write_bytes(expand(files, top, tmp_path))
        r = subprocess.run([exe, str(path)], capture_output=True, text=True, timeout=60)
        assert r.returncode == 0, r.stderr
        assert "Successfully Parsed XML" in r.stdout


TOPS = [
    ("my_robot_gz.urdf.xacro", "my_robot.urdf"),
    ("standalone_arm_gz.urdf.xacro", "standalone_arm.urdf"),
]


@pytest.mark.parametrize(("top", "course"), TOPS)
def test_jazzy_urdf_passes_armcli_check_with_the_pd_bound(
    files: Mapping[str, bytes], spec: RobotSpec, tmp_path: Path, top: str, course: str
) -> None:
    urdf = parse_urdf(expand(files, top, tmp_path), top)
    res = check_urdf(urdf, CheckOptions(spec=spec))
    assert [f for f in res.findings if f.severity == "error"] == []
    # effort interface: the PD torque loop, bounded as for the course URDF; the example's
    # gains are stable in both loops (docs/check.md). The standalone arm hangs from a
    # massless `world` link, so KDL's root-inertia warning is gone too.
    assert res.summary is not None and res.summary.stability is not None
    assert res.summary.stability.explicit.stable and res.summary.stability.implicit.stable
    assert {f.rule for f in res.findings} == set()


@pytest.mark.parametrize(("top", "course"), TOPS)
def test_jazzy_urdf_has_the_course_dynamics_in_pinocchio(
    files: Mapping[str, bytes], built_dir: Path, tmp_path: Path, top: str, course: str
) -> None:
    import pinocchio as pin

    ours = pin.buildModelFromXML(expand(files, top, tmp_path).decode())
    ref = pin.buildModelFromUrdf(str(built_dir / course))
    assert list(ours.names) == list(ref.names)
    pin.seed(0)
    for _ in range(10):
        q = pin.randomConfiguration(ref)
        M_ours = pin.crba(ours, ours.createData(), q)
        M_ref = pin.crba(ref, ref.createData(), q)
        assert np.max(np.abs(M_ours - M_ref)) < RIGID_TOL


def test_standalone_arm_is_welded_to_the_world(files: Mapping[str, bytes], tmp_path: Path) -> None:
    urdf = parse_urdf(expand(files, "standalone_arm_gz.urdf.xacro", tmp_path), "arm")
    anchor = next(j for j in urdf.joints if j.name == WORLD_JOINT)
    assert (anchor.type, anchor.parent, anchor.child) == ("fixed", "world", "arm_base_link")
    assert urdf.link("world") is not None and urdf.link("world").inertial is None


def test_cli_target_choice_and_one_line_error(tmp_path: Path) -> None:
    spec = str(ROOT / LABEL)
    r = run_cli(
        ["ros-package", spec, "-o", tmp_path / "a", "--samples", "10", "--target", "noetic"]
    )
    assert r.returncode == 2 and "humble-classic" in r.stderr and "jazzy" in r.stderr
    assert not (tmp_path / "a").exists()
    bad = tmp_path / "no_gains.yaml"
    bad.write_text(
        (ROOT / LABEL).read_text().replace("    forearm_hand_joint: {kp: 50, kd: 1.5}\n", "")
    )
    r = run_cli(["ros-package", bad, "-o", tmp_path / "b", "--samples", "10", "--target", "jazzy"])
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert "no_gains.yaml" in r.stderr and "control.gains" in r.stderr
    assert not (tmp_path / "b").exists()
