"""The three ROS 2 packages, verified without ROS: XML, CMake installs, launch ASTs, xacro, names.

Launch files are never run here; their syntax trees are read for the packages,
executables and files they use, and each of those is checked against what the
generated packages contain or declare as dependencies.
"""

from __future__ import annotations

import ast
import py_compile
import re
from collections.abc import Mapping
from pathlib import Path

import pytest
import yaml
from catkin_pkg.package import parse_package_string
from lxml import etree

from armcli.compiler.xacro_writer import xacro_files
from armcli.errors import InputError
from armcli.io.files import write_tree_atomic
from armcli.ros.launch import module_constants
from armcli.ros.packages import RosPackages, ros_packages
from armcli.spec.load import load_spec, loads_spec
from armcli.spec.model import RobotSpec
from tests.helpers import ROOT, run_cli

SAMPLES = 300  # enough for the tests; the CLI default is the Setup Assistant's 10000
LABEL = "specs/my_robot.yaml"
DESC, BRINGUP, MOVEIT = "my_robot_description", "my_robot_bringup", "my_robot_moveit_config"
# issue 5: what the display launch file needs at run time
DISPLAY_DEPENDS = {"urdf", "xacro", "robot_state_publisher", "joint_state_publisher_gui", "rviz2"}
# moveit_configs_utils (MoveItConfigsBuilder.to_moveit_configs and generate_demo_launch) loads
# these from the MoveIt package; a missing one is an exception at launch time
MOVEIT_REQUIRED = [
    "config/my_robot.urdf.xacro",
    "config/my_robot.srdf",
    "config/kinematics.yaml",
    "config/joint_limits.yaml",
    "config/moveit_controllers.yaml",
    "config/ros2_controllers.yaml",
    "config/pilz_cartesian_limits.yaml",
    "config/moveit.rviz",
    "launch/rsp.launch.py",
    "launch/move_group.launch.py",
    "launch/moveit_rviz.launch.py",
    "launch/warehouse_db.launch.py",
    "launch/spawn_controllers.launch.py",
]


@pytest.fixture(scope="module")
def spec(default_spec_path: Path) -> RobotSpec:
    return load_spec(default_spec_path)


@pytest.fixture(scope="module")
def pkgs(spec: RobotSpec) -> RosPackages:
    return ros_packages(spec, label=LABEL, samples=SAMPLES, seed=0)


@pytest.fixture(scope="module")
def files(pkgs: RosPackages) -> Mapping[str, bytes]:
    return pkgs.files


@pytest.fixture(scope="module")
def out_dir(files: Mapping[str, bytes], tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("ros")
    write_tree_atomic(out, files)
    return out


@pytest.fixture(scope="module")
def urdf(built_dir: Path) -> etree._Element:
    return etree.parse(str(built_dir / "my_robot.urdf")).getroot()


def _names(root: etree._Element, tag: str) -> set[str]:
    return {el.get("name", "") for el in root.findall(tag)}


def _package_files(files: Mapping[str, bytes], pkg: str) -> dict[str, bytes]:
    return {p[len(pkg) + 1 :]: d for p, d in files.items() if p.startswith(pkg + "/")}


def _exec_depends(files: Mapping[str, bytes], pkg: str) -> set[str]:
    manifest = parse_package_string(files[f"{pkg}/package.xml"].decode())
    return {d.name for d in manifest.exec_depends}


def test_three_packages_and_nothing_else(files: Mapping[str, bytes]) -> None:
    assert {p.split("/", 1)[0] for p in files} == {DESC, BRINGUP, MOVEIT}


def test_every_xml_file_is_well_formed(files: Mapping[str, bytes]) -> None:
    xml = [p for p in files if p.endswith((".xml", ".xacro", ".srdf"))]
    assert len(xml) >= 13  # 3 package.xml, 7 course xacro files, srdf, 2 MoveIt xacro files
    for p in xml:
        etree.fromstring(files[p])


def test_package_xml_is_valid_format_3(files: Mapping[str, bytes]) -> None:
    for pkg in (DESC, BRINGUP, MOVEIT):
        warnings: list[str] = []
        manifest = parse_package_string(files[f"{pkg}/package.xml"].decode(), warnings=warnings)
        manifest.validate(warnings=warnings)
        assert warnings == []
        assert manifest.name == pkg
        assert manifest.package_format == 3
        assert [d.name for d in manifest.buildtool_depends] == ["ament_cmake"]
        assert manifest.get_build_type() == "ament_cmake"
    assert _exec_depends(files, DESC) >= DISPLAY_DEPENDS
    assert {DESC, "gazebo_ros", "gazebo_plugins"} <= _exec_depends(files, BRINGUP)
    assert {DESC, "moveit_configs_utils", "moveit_kinematics"} <= _exec_depends(files, MOVEIT)


def _cmake_installs(text: str) -> tuple[list[str], list[str]]:
    dirs = [d for m in re.findall(r"DIRECTORY ([^\n]+)", text) for d in m.split()]
    plain = [f for m in re.findall(r"FILES ([^\n]+)", text) for f in m.split()]
    return dirs, plain


def test_cmake_installs_exactly_what_the_package_has(files: Mapping[str, bytes]) -> None:
    for pkg in (DESC, BRINGUP, MOVEIT):
        own = _package_files(files, pkg)
        text = own["CMakeLists.txt"].decode()
        assert f"project({pkg})" in text and "ament_package()" in text
        dirs, plain = _cmake_installs(text)
        for d in dirs:
            assert any(p.startswith(d + "/") for p in own), f"{pkg}: installs missing {d}/"
        for f in plain:
            assert f in own, f"{pkg}: installs missing {f}"
        uninstalled = [
            p
            for p in own
            if p not in ("package.xml", "CMakeLists.txt")
            and p not in plain
            and p.split("/", 1)[0] not in dirs
        ]
        assert uninstalled == []
    desc_dirs = _cmake_installs(files[f"{DESC}/CMakeLists.txt"].decode())[0]
    assert desc_dirs == ["launch", "rviz", "urdf"]


def test_description_holds_the_build_xacro_set(files: Mapping[str, bytes], spec: RobotSpec) -> None:
    expected = xacro_files(spec, LABEL)
    assert _package_files(files, DESC).keys() >= {f"urdf/{n}" for n in expected}
    for name, data in expected.items():
        assert files[f"{DESC}/urdf/{name}"] == data


# -- launch files: compile, then read the syntax tree --------------------------------------


class LaunchFacts:
    """Packages, executables and files a launch file uses, read from its syntax tree."""

    def __init__(self, source: bytes, name: str) -> None:
        compile(source, name, "exec")  # what py_compile does, without writing a .pyc
        tree = ast.parse(source)
        self.consts = module_constants(tree)
        self.shares: dict[str, str] = {}  # variable -> package of get_package_share_directory
        self.calls: list[tuple[str, ast.Call]] = []
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Assign)
                and isinstance(node.value, ast.Call)
                and self._name(node.value.func) == "get_package_share_directory"
            ):
                target = node.targets[0]
                assert isinstance(target, ast.Name)
                self.shares[target.id] = str(self.value(node.value.args[0]))
            if isinstance(node, ast.Call):
                self.calls.append((self._name(node.func), node))

    @staticmethod
    def _name(func: ast.expr) -> str:
        return func.id if isinstance(func, ast.Name) else getattr(func, "attr", "")

    def value(self, node: ast.expr) -> object:
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            return self.consts.get(node.id, self.shares.get(node.id, f"<{node.id}>"))
        if isinstance(node, ast.List):
            return [self.value(e) for e in node.elts]
        return None

    def nodes(self) -> list[dict[str, object]]:
        """keyword arguments of every launch_ros Node(...)"""
        return [
            {kw.arg or "": self.value(kw.value) for kw in call.keywords}
            for name, call in self.calls
            if name == "Node"
        ]

    def joined_paths(self) -> list[tuple[str, str]]:
        """(package, relative path) of every os.path.join(<share of package>, ...)"""
        out = []
        for name, call in self.calls:
            first = call.args[0] if call.args else None
            if name == "join" and isinstance(first, ast.Name) and first.id in self.shares:
                parts = [str(self.value(a)) for a in call.args[1:]]
                out.append((self.shares[first.id], "/".join(parts)))
        return out


def _launch(files: Mapping[str, bytes], path: str) -> LaunchFacts:
    return LaunchFacts(files[path], path)


def test_every_launch_file_compiles(out_dir: Path, tmp_path: Path) -> None:
    launches = sorted(out_dir.rglob("*.launch.py"))
    assert len(launches) == 8  # display, gazebo, six MoveIt launch files
    for i, path in enumerate(launches):
        py_compile.compile(str(path), cfile=str(tmp_path / f"{i}.pyc"), doraise=True)
        tree = ast.parse(path.read_bytes())
        assert "generate_launch_description" in {
            n.name for n in tree.body if isinstance(n, ast.FunctionDef)
        }


def _check_nodes_and_paths(
    facts: LaunchFacts, files: Mapping[str, bytes], pkg: str, external: set[str]
) -> None:
    depends = _exec_depends(files, pkg)
    for node in facts.nodes():
        assert node["package"] in depends, f"{pkg} launches {node['package']} without depending"
    for share_pkg, rel in facts.joined_paths():
        if share_pkg in (DESC, BRINGUP, MOVEIT):
            own = _package_files(files, share_pkg)
            assert rel in own or any(p.startswith(rel) for p in own), f"{share_pkg}/{rel}"
        else:
            assert share_pkg in depends and f"{share_pkg}/{rel}" in external


def test_display_launch(files: Mapping[str, bytes], built_dir: Path) -> None:
    facts = _launch(files, f"{DESC}/launch/display.launch.py")
    c = facts.consts
    assert c["DESCRIPTION_PKG"] == DESC
    for key in ("ROBOT_XACRO", "STANDALONE_XACRO"):
        assert f"{DESC}/urdf/{c[key]}" in files
    assert f"{DESC}/rviz/{c['RVIZ_CONFIG']}" in files
    # the RViz fixed frames are the roots of the two URDFs
    robot = etree.parse(str(built_dir / "my_robot.urdf")).getroot()
    arm = etree.parse(str(built_dir / "standalone_arm.urdf")).getroot()
    assert c["ROBOT_ROOT"] == "base_footprint" and c["ROBOT_ROOT"] in _names(robot, "link")
    assert c["STANDALONE_ROOT"] == "arm_base_link" and c["STANDALONE_ROOT"] in _names(arm, "link")
    packages = {n["package"]: n["executable"] for n in facts.nodes()}
    assert packages == {
        "robot_state_publisher": "robot_state_publisher",
        "joint_state_publisher_gui": "joint_state_publisher_gui",
        "rviz2": "rviz2",
    }
    _check_nodes_and_paths(facts, files, DESC, set())


def test_gazebo_launch(files: Mapping[str, bytes]) -> None:
    facts = _launch(files, f"{BRINGUP}/launch/my_robot_gazebo.launch.py")
    nodes = {f"{n['package']}/{n['executable']}": n for n in facts.nodes()}
    spawn = nodes["gazebo_ros/spawn_entity.py"]
    assert spawn["arguments"] == ["-topic", "robot_description", "-entity", "my_robot"]
    rsp = facts.calls[[n for n, _ in facts.calls].index("Node")][1]
    params = next(kw.value for kw in rsp.keywords if kw.arg == "parameters")
    assert isinstance(params, ast.List) and isinstance(params.elts[0], ast.Dict)
    keys = [facts.value(k) for k in params.elts[0].keys if k is not None]
    values = [facts.value(v) for v in params.elts[0].values]
    assert dict(zip(keys, values, strict=True))["use_sim_time"] is True
    assert "robot_state_publisher/robot_state_publisher" in nodes
    assert ("gazebo_ros", "launch/gazebo.launch.py") in facts.joined_paths()
    assert facts.consts["DESCRIPTION_PKG"] == DESC
    _check_nodes_and_paths(facts, files, BRINGUP, {"gazebo_ros/launch/gazebo.launch.py"})


def test_moveit_launches_find_every_file_they_load(files: Mapping[str, bytes]) -> None:
    own = _package_files(files, MOVEIT)
    for rel in MOVEIT_REQUIRED:
        assert rel in own, rel
    assert [p for p in own if p.endswith("_controllers.yaml")] == [
        "config/moveit_controllers.yaml",  # MoveItConfigsBuilder prefers moveit_ over ros2_
        "config/ros2_controllers.yaml",
    ]
    for rel in (p for p in own if p.startswith("launch/")):
        facts = _launch(files, f"{MOVEIT}/{rel}")
        (builder,) = [c for n, c in facts.calls if n == "MoveItConfigsBuilder"]
        assert facts.value(builder.args[0]) == "my_robot"
        assert {kw.arg: facts.value(kw.value) for kw in builder.keywords} == {
            "package_name": MOVEIT
        }
        tree = ast.parse(own[rel])
        imported = {
            a.name
            for n in tree.body
            if isinstance(n, ast.ImportFrom) and n.module == "moveit_configs_utils.launches"
            for a in n.names
        }
        called = {n for n, _ in facts.calls if n.startswith("generate_")}
        assert len(imported) == 1 and imported == called


# -- names and values across files ------------------------------------------------------


def test_controller_and_srdf_names_exist_in_the_urdf(
    files: Mapping[str, bytes], urdf: etree._Element
) -> None:
    links, joints = _names(urdf, "link"), _names(urdf, "joint")
    srdf = etree.fromstring(files[f"{MOVEIT}/config/my_robot.srdf"])
    for d in srdf.findall("disable_collisions"):
        assert {d.get("link1"), d.get("link2")} <= links
    ctrl = yaml.safe_load(files[f"{MOVEIT}/config/ros2_controllers.yaml"])
    assert set(ctrl["arm_controller"]["ros__parameters"]["joints"]) <= joints
    moveit = yaml.safe_load(files[f"{MOVEIT}/config/moveit_controllers.yaml"])
    assert set(moveit["moveit_simple_controller_manager"]["arm_controller"]["joints"]) <= joints
    init = yaml.safe_load(files[f"{MOVEIT}/config/initial_positions.yaml"])
    assert set(init["initial_positions"]) <= joints
    limits = yaml.safe_load(files[f"{MOVEIT}/config/joint_limits.yaml"])
    assert set(limits["joint_limits"]) <= joints
    kin = yaml.safe_load(files[f"{MOVEIT}/config/kinematics.yaml"])
    assert set(kin) <= _names(srdf, "group")


def test_rviz_configs(files: Mapping[str, bytes], urdf: etree._Element) -> None:
    display = yaml.safe_load(files[f"{DESC}/rviz/display.rviz"])["Visualization Manager"]
    assert display["Global Options"]["Fixed Frame"] == "base_footprint"
    classes = {d["Class"] for d in display["Displays"]}
    assert {"rviz_default_plugins/RobotModel", "rviz_default_plugins/TF"} <= classes
    moveit = yaml.safe_load(files[f"{MOVEIT}/config/moveit.rviz"])["Visualization Manager"]
    assert moveit["Global Options"]["Fixed Frame"] in _names(urdf, "link")
    (planning,) = [d for d in moveit["Displays"] if d["Class"].endswith("MotionPlanning")]
    assert planning["Planning Request"]["Planning Group"] == "arm"


def _expand(path: Path, out_dir: Path, monkeypatch: pytest.MonkeyPatch) -> etree._Element:
    """Run the real xacro, resolving $(find pkg) to the generated packages."""
    import xacro
    import xacro.substitution_args

    monkeypatch.setattr(xacro.substitution_args, "_eval_find", lambda pkg: str(out_dir / pkg))
    doc = xacro.process_file(str(path))
    return etree.fromstring(doc.toxml().encode())


def test_xacro_in_the_description_expands_to_the_built_urdf(
    out_dir: Path, urdf: etree._Element, monkeypatch: pytest.MonkeyPatch
) -> None:
    expanded = _expand(out_dir / DESC / "urdf" / "my_robot.urdf.xacro", out_dir, monkeypatch)
    assert _names(expanded, "link") == _names(urdf, "link")
    assert _names(expanded, "joint") == _names(urdf, "joint")


def test_moveit_urdf_adds_ros2_control_for_the_arm(
    out_dir: Path, files: Mapping[str, bytes], urdf: etree._Element, monkeypatch: pytest.MonkeyPatch
) -> None:
    root = _expand(out_dir / MOVEIT / "config" / "my_robot.urdf.xacro", out_dir, monkeypatch)
    assert _names(root, "link") == _names(urdf, "link")  # the course description, unchanged
    (rc,) = root.findall("ros2_control")
    assert rc.findtext("hardware/plugin") == "mock_components/GenericSystem"
    init = yaml.safe_load(files[f"{MOVEIT}/config/initial_positions.yaml"])["initial_positions"]
    ctrl = yaml.safe_load(files[f"{MOVEIT}/config/ros2_controllers.yaml"])
    joints = ctrl["arm_controller"]["ros__parameters"]["joints"]
    commanded = [
        j.get("name") for j in rc.findall("joint") if j.find("command_interface") is not None
    ]
    assert commanded == joints
    # the wheels are there too (state only), so joint_state_broadcaster publishes every joint
    movable = {j.get("name") for j in urdf.findall("joint") if j.get("type") != "fixed"}
    assert _names(rc, "joint") == movable
    for j in rc.findall("joint"):
        value = j.findtext("state_interface[@name='position']/param[@name='initial_value']")
        assert float(value or "nan") == init[j.get("name")]
        commands = {c.get("name") for c in j.findall("command_interface")}
        if j.get("name") in joints:
            assert commands == set(ctrl["arm_controller"]["ros__parameters"]["command_interfaces"])


# -- determinism, atomicity, the command -------------------------------------------------


def test_same_inputs_same_bytes(spec: RobotSpec, pkgs: RosPackages) -> None:
    again = ros_packages(spec, label=LABEL, samples=SAMPLES, seed=0)
    assert again.files == pkgs.files


def test_command_writes_the_tree_and_rewrites_identically(root: Path, tmp_path: Path) -> None:
    out = tmp_path / "ros"
    args = ("ros-package", "specs/my_robot.yaml", "-o", str(out), "--samples", "200")
    first = run_cli(args, root)
    assert first.returncode == 0, first.stderr
    assert "my_robot_moveit_config" in first.stdout
    assert "named pose" not in first.stderr  # no shipped pose collides (test_collision_matrix)
    snapshot = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert len(snapshot) == 34  # 33 package files + the armcli marker
    second = run_cli(args, root)
    assert second.returncode == 0
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == snapshot


def test_bad_spec_gives_one_line_and_no_output(root: Path, tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    text = (root / "specs" / "my_robot.yaml").read_text()
    bad.write_text(text.replace("controller_update_rate: 1000", "controller_update_rate: 999.5"))
    out = tmp_path / "ros"
    proc = run_cli(["ros-package", str(bad), "-o", str(out)], root)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "control.controller_update_rate" in lines[0]
    assert str(bad) in lines[0]
    assert not out.exists()


def _edited_spec(default_spec_path: Path, **changes: object) -> RobotSpec:
    data = yaml.safe_load(default_spec_path.read_text())
    for key, value in changes.items():
        if value is None:
            del data[key]
        else:
            data[key] = value
    return loads_spec(yaml.safe_dump(data), "edited.yaml")


def test_arm_only_spec_uses_the_standalone_arm_everywhere(default_spec_path: Path) -> None:
    spec = _edited_spec(default_spec_path, mobile_base=None, mount=None)
    files = ros_packages(spec, samples=50).files
    display = _launch(files, f"{DESC}/launch/display.launch.py").consts
    assert display["ROBOT_XACRO"] == "standalone_arm.urdf.xacro"
    assert display["ROBOT_ROOT"] == "arm_base_link"
    moveit_xacro = etree.fromstring(files[f"{MOVEIT}/config/my_robot.urdf.xacro"])
    includes = [el.get("filename", "") for el in moveit_xacro if "include" in str(el.tag)]
    assert includes[0] == f"$(find {DESC})/urdf/standalone_arm.urdf.xacro"
    srdf = etree.fromstring(files[f"{MOVEIT}/config/my_robot.srdf"])
    pairs = {(d.get("link1"), d.get("link2")) for d in srdf.findall("disable_collisions")}
    # three arm links: arm_base-forearm and forearm-hand are adjacent; arm_base-hand is left
    assert pairs >= {("arm_base_link", "forearm_link"), ("forearm_link", "hand_link")}


def test_a_name_ros_cannot_use_is_refused(default_spec_path: Path) -> None:
    spec = _edited_spec(default_spec_path, name="MyRobot")
    with pytest.raises(InputError) as err:
        ros_packages(spec, samples=1, source="edited.yaml")
    assert err.value.field == "name"


@pytest.mark.parametrize("spec_path", sorted(ROOT.glob("specs/*.yaml")))
def test_every_spec_gives_packages(spec_path: Path) -> None:
    spec = load_spec(spec_path)
    files = ros_packages(spec, samples=20).files
    for pkg in (f"{spec.name}_description", f"{spec.name}_bringup", f"{spec.name}_moveit_config"):
        assert f"{pkg}/package.xml" in files and f"{pkg}/CMakeLists.txt" in files
