"""Spec -> three ROS 2 packages: description, bringup (Gazebo) and MoveIt config.

`<name>_description` holds the xacro set exactly as `build` writes it plus a
display launch file and an RViz config; `<name>_bringup` starts Gazebo with
the robot; `<name>_moveit_config` is what the MoveIt Setup Assistant would
produce, but computed from the spec (SRDF with a sampled collision matrix,
kinematics, limits, controllers). Everything is built in memory first and
written with one atomic tree swap, so a failure leaves no partial packages.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lxml import etree

from armcli.compiler.meshfiles import MeshNames, package_of, spec_mesh_names
from armcli.compiler.xacro_writer import GENERATED, STANDALONE_ARM, top_level_files, xacro_files
from armcli.defaults import ROS_TARGETS, STANDALONE_ARM_URDF
from armcli.errors import InputError
from armcli.io.files import write_tree_atomic
from armcli.io.outdir import resolve_output_dir
from armcli.io.packages import PackageLookup
from armcli.ros import jazzy
from armcli.ros import moveit as mc
from armcli.ros.collision_matrix import (
    DEFAULT_SAMPLES,
    DEFAULT_SEED,
    CollisionMatrix,
    compute_collision_matrix,
)
from armcli.ros.controller_rate import Control, jazzy_control
from armcli.ros.copying import mesh_files
from armcli.ros.depends import BRINGUP_DEPENDS, DESCRIPTION_DEPENDS, MOVEIT_DEPENDS
from armcli.ros.jazzy_readme import readme as jazzy_readme
from armcli.ros.launch import render
from armcli.ros.ros2_control import moveit_urdf_xacro, ros2_control_xacro
from armcli.ros.rviz import display_rviz, moveit_rviz
from armcli.ros.srdf import chain_joints, srdf_bytes
from armcli.spec.graph import root_links
from armcli.spec.load import load_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.meshes import confined_mesh_xml
from armcli.urdf.read import parse_urdf
from armcli.urdf.source import lookup_for, spec_urdfs

FORMAT3_SCHEMA = "http://download.ros.org/schema/package_format3.xsd"
DISPLAY_RVIZ = "display.rviz"
PACKAGE_NAME = re.compile(r"^[a-z][a-z0-9_]*$")  # REP 144
TARGETS = ROS_TARGETS
DEFAULT_TARGET = TARGETS[0]
MOVEIT_LAUNCHES = {  # launch file -> (moveit_configs_utils generator, what it starts)
    "demo.launch.py": ("generate_demo_launch", "MoveIt demo on mock hardware with RViz."),
    "move_group.launch.py": ("generate_move_group_launch", "The move_group node."),
    "moveit_rviz.launch.py": ("generate_moveit_rviz_launch", "RViz with MotionPlanning."),
    "rsp.launch.py": ("generate_rsp_launch", "robot_state_publisher for the MoveIt URDF."),
    "spawn_controllers.launch.py": ("generate_spawn_controllers_launch", "Controller spawners."),
    "warehouse_db.launch.py": ("generate_warehouse_db_launch", "The warehouse database."),
}


@dataclass(frozen=True)
class PackageInfo:
    """package.xml metadata the spec does not hold."""

    maintainer: str = "armcli"
    email: str = "armcli@example.com"
    license: str = "TODO"
    version: str = "0.1.0"


@dataclass(frozen=True)
class Names:
    """Every name the three packages use for each other, derived from the spec name."""

    robot: str
    description: str
    bringup: str
    moveit: str
    robot_xacro: str  # top-level xacro of the whole robot
    robot_root: str  # its root link (RViz fixed frame)
    standalone_root: str
    gazebo_launch: str
    srdf: str

    @staticmethod
    def of(spec: RobotSpec, source: str | None = None) -> Names:
        """Every package, file and frame name, derived from the spec's name.

        Raises:
            InputError: the spec name is not a valid ROS package name.
        """
        if not PACKAGE_NAME.match(spec.name):
            raise InputError(
                f"{spec.name!r}: ROS package names need lower case letters, digits and _",
                file=source,
                field="name",
            )
        whole = top_level_files(spec).get(f"{spec.name}.urdf", STANDALONE_ARM)
        root = spec.arm_root()
        base = spec.mounted_base()
        if base is not None and whole != STANDALONE_ARM:
            root = root_links(base.links, (j.child for j in base.joints.values()))[0]
        return Names(
            robot=spec.name,
            description=f"{spec.name}_description",
            bringup=f"{spec.name}_bringup",
            moveit=f"{spec.name}_moveit_config",
            robot_xacro=whole,
            robot_root=root,
            standalone_root=spec.arm_root(),
            gazebo_launch=f"{spec.name}_gazebo.launch.py",
            srdf=f"config/{spec.name}.srdf",
        )


@dataclass(frozen=True)
class RosPackages:
    """The three packages in memory, before the one atomic write, with their names and matrix."""

    files: Mapping[str, bytes]  # path relative to the output directory -> content
    names: Names
    matrix: CollisionMatrix


def package_xml(name: str, description: str, depends: list[str], info: PackageInfo) -> bytes:
    """package.xml format 3 for an ament_cmake package that only installs files."""
    root = etree.Element("package", format="3")
    for tag, text in (("name", name), ("version", info.version), ("description", description)):
        etree.SubElement(root, tag).text = text
    etree.SubElement(root, "maintainer", email=info.email).text = info.maintainer
    etree.SubElement(root, "license").text = info.license
    etree.SubElement(root, "buildtool_depend").text = "ament_cmake"
    for dep in depends:
        etree.SubElement(root, "exec_depend").text = dep
    export = etree.SubElement(root, "export")
    etree.SubElement(export, "build_type").text = "ament_cmake"
    etree.indent(root, space="  ")
    body = etree.tostring(root, encoding="unicode")
    head = (
        '<?xml version="1.0"?>\n'
        f'<?xml-model href="{FORMAT3_SCHEMA}" schematypens="http://www.w3.org/2001/XMLSchema"?>\n'
    )
    return (head + body + "\n").encode("utf-8")


def cmakelists(name: str, directories: Sequence[str], files: Sequence[str] = ()) -> bytes:
    """ament_cmake CMakeLists.txt installing `directories` (and `files`) into share/<name>."""
    lines = [
        "cmake_minimum_required(VERSION 3.8)",
        f"project({name})",
        "",
        "find_package(ament_cmake REQUIRED)",
        "",
        "install(",
        f"  DIRECTORY {' '.join(sorted(directories))}",
        "  DESTINATION share/${PROJECT_NAME}",
        ")",
    ]
    if files:
        lines += ["install(", f"  FILES {' '.join(files)}", "  DESTINATION share/${PROJECT_NAME}"]
        lines += [")"]
    lines += ["", "ament_package()", ""]
    return "\n".join(lines).encode("utf-8")


def _dirs(files: Mapping[str, bytes]) -> list[str]:
    """Top-level directories of a package's files (what CMake has to install)."""
    return sorted({p.split("/", 1)[0] for p in files if "/" in p})


def _package(
    name: str, about: str, depends: list[str], files: dict[str, bytes], info: PackageInfo
) -> dict[str, bytes]:
    dot_files = sorted(p for p in files if "/" not in p and p.startswith("."))
    out = dict(files)
    out["package.xml"] = package_xml(name, about, depends, info)
    out["CMakeLists.txt"] = cmakelists(name, _dirs(files), dot_files)
    return {f"{name}/{p}": data for p, data in sorted(out.items())}


def _launch_values(n: Names) -> dict[str, str]:
    return {
        "description_pkg": n.description,
        "bringup_pkg": n.bringup,
        "robot_xacro": n.robot_xacro,
        "standalone_xacro": STANDALONE_ARM,
        "robot_root": n.robot_root,
        "standalone_root": n.standalone_root,
        "rviz_config": DISPLAY_RVIZ,
        "gazebo_launch": n.gazebo_launch,
        "entity": n.robot,
    }


def description_files(
    spec: RobotSpec,
    n: Names,
    label: str,
    info: PackageInfo,
    extra: Mapping[str, bytes] | None = None,
) -> dict[str, bytes]:
    """The `<name>_description` files: the `build` xacro set, a display launch and RViz config.

    `extra` adds xacro files under `urdf/` (the Jazzy top levels).
    """
    note = GENERATED.format(spec=label)
    names = MeshNames(spec.base_dir, package=n.description)
    xacros = {**xacro_files(spec, label, names, hardware=False), **(extra or {})}
    files = {f"urdf/{name}": data for name, data in xacros.items()}
    files.update(mesh_files(spec))
    files["launch/display.launch.py"] = render("display.launch.py.tmpl", _launch_values(n), note)
    files[f"rviz/{DISPLAY_RVIZ}"] = mc.dump_yaml(display_rviz(n.robot_root), note)
    about = f"Robot description (xacro, URDF, RViz) of {n.robot}. {note}"
    others = sorted({p for m in spec_mesh_names(spec) if (p := package_of(m)) is not None})
    depends = [*DESCRIPTION_DEPENDS, *(p for p in others if p != n.description)]
    return _package(n.description, about, depends, files, info)


def bringup_files(n: Names, note: str, info: PackageInfo) -> dict[str, bytes]:
    """The `<name>_bringup` files: a launch file that starts Gazebo with the robot."""
    launch = render("gazebo.launch.py.tmpl", _launch_values(n), note)
    about = f"Gazebo bringup of {n.robot}. {note}"
    depends = [n.description, *BRINGUP_DEPENDS]
    return _package(n.bringup, about, depends, {f"launch/{n.gazebo_launch}": launch}, info)


def _moveit_yaml(spec: RobotSpec, urdf_xml: bytes) -> dict[str, dict[str, Any]]:
    urdf = parse_urdf(urdf_xml, f"{spec.name}.urdf")
    return {
        "kinematics.yaml": mc.kinematics(spec),
        "joint_limits.yaml": mc.joint_limits(urdf, chain_joints(spec)),
        "ros2_controllers.yaml": mc.ros2_controllers(spec),
        "moveit_controllers.yaml": mc.moveit_controllers(spec),
        "initial_positions.yaml": mc.initial_positions(spec),
        "pilz_cartesian_limits.yaml": mc.pilz_cartesian_limits(),
    }


def moveit_files(
    spec: RobotSpec,
    n: Names,
    urdf_xml: bytes,
    matrix: CollisionMatrix,
    note: str,
    info: PackageInfo,
    target: str = DEFAULT_TARGET,
) -> dict[str, bytes]:
    """The `<name>_moveit_config` files: SRDF, config YAML, ros2_control xacro, RViz, launches."""
    yamls = _moveit_yaml(spec, urdf_xml)
    if target == "jazzy":
        yamls["moveit_controllers.yaml"] = jazzy.moveit_controllers(spec)
    files = {f"config/{name}": mc.dump_yaml(data, note) for name, data in yamls.items()}
    urdf_xacro = f"config/{n.robot}.urdf.xacro"
    files[n.srdf] = srdf_bytes(spec, matrix, note)
    files[urdf_xacro] = moveit_urdf_xacro(n.robot, n.description, n.robot_xacro, note)
    files[f"config/{n.robot}.ros2_control.xacro"] = ros2_control_xacro(spec, note)
    files["config/moveit.rviz"] = mc.dump_yaml(moveit_rviz(n.robot_root), note)
    files[".setup_assistant"] = mc.dump_yaml(mc.setup_assistant(n.moveit, urdf_xacro, n.srdf), note)
    for launch, (generator, what) in MOVEIT_LAUNCHES.items():
        values = {"robot": n.robot, "moveit_pkg": n.moveit, "generator": generator}
        files[f"launch/{launch}"] = render("moveit.launch.py.tmpl", values, f"{what}\n\n{note}")
    if target == "jazzy":
        gz_launch = jazzy.move_group_launch(n.robot, n.moveit, note)
        files[f"launch/{jazzy.MOVE_GROUP_LAUNCH}"] = gz_launch
    about = f"MoveIt 2 configuration of {n.robot}. {note}"
    depends = sorted({*MOVEIT_DEPENDS, *(jazzy.MOVEIT_DEPENDS if target == "jazzy" else ())})
    return _package(n.moveit, about, [n.description, *depends], files, info)


def ros_packages(
    spec: RobotSpec,
    *,
    label: str = "the armcli spec",
    samples: int = DEFAULT_SAMPLES,
    seed: int = DEFAULT_SEED,
    info: PackageInfo = PackageInfo(),
    source: str | None = None,
    target: str = DEFAULT_TARGET,
    packages: PackageLookup | None = None,
) -> RosPackages:
    """All files of the three packages, in memory; deterministic for fixed samples and seed.

    `source` (the spec file) is only used to point at it in input errors. `target`
    "jazzy" swaps the Gazebo classic bringup for Gazebo Harmonic + ros2_control.
    `packages`: where `package://` meshes are (--package-dir, the environment; the spec's
    recorded `packages` are added), for the collision matrix's geometry.
    """
    if target not in TARGETS:
        raise InputError(f"unknown target {target!r}; known: {', '.join(TARGETS)}")
    n = Names.of(spec, source)
    mc.controller_update_rate(spec, source)  # refuse bad input before the slow sampling
    if target == "jazzy":
        jazzy.required_gains(spec, source)
    urdfs = spec_urdfs(spec)
    urdf_xml = urdfs.get(f"{n.robot}.urdf", urdfs[STANDALONE_ARM_URDF])
    poses = {name: spec.pose(name) for name in spec.poses}
    control = jazzy_control(spec, urdf_xml, source) if target == "jazzy" else None
    local = confined_mesh_xml(
        urdf_xml,
        source or n.robot_xacro,
        lookup_for(spec, packages),
        base_dir=spec.base_dir,
        collision_only=True,  # visual meshes may be another package's, not installed here
    )
    matrix = compute_collision_matrix(
        local, samples=samples, seed=seed, source=n.robot_xacro, poses=poses
    )
    note = GENERATED.format(spec=label)
    if control is not None:
        files = jazzy_files(spec, n, label, info, source, control)
    else:
        files = {**description_files(spec, n, label, info), **bringup_files(n, note, info)}
    files.update(moveit_files(spec, n, urdf_xml, matrix, note, info, target))
    return RosPackages(files=dict(sorted(files.items())), names=n, matrix=matrix)


def jazzy_files(
    spec: RobotSpec,
    n: Names,
    label: str,
    info: PackageInfo,
    source: str | None,
    control: Control | None = None,
) -> dict[str, bytes]:
    """Description (course xacro + Jazzy top levels), Gazebo Harmonic bringup (`control`)."""
    note = GENERATED.format(spec=label)
    tops = jazzy.description_xacros(spec, n.bringup, note)
    whole = jazzy.TOP.format(name=n.robot)
    launch = jazzy.GZ_LAUNCH.format(name=n.robot)
    values = {
        **_launch_values(n),
        "robot_xacro": whole if whole in tops else jazzy.STANDALONE,
        "standalone_xacro": jazzy.STANDALONE,
        "controllers": jazzy.controllers_file(n.robot),
        "bridge": jazzy.bridge_file(n.robot),
        "gz_launch": launch,
        "arm_controller": mc.ARM_CONTROLLER,
        "joint_state_broadcaster": mc.JOINT_STATE_BROADCASTER,
    }
    files = {
        f"config/{jazzy.controllers_file(n.robot)}": mc.dump_yaml(
            jazzy.controllers(spec, source, control.holding if control else None), note
        ),
        f"config/{jazzy.bridge_file(n.robot)}": jazzy.bridge_yaml(spec, note),
        f"launch/{launch}": jazzy.bringup_launch(values, note),
        "README.md": jazzy_readme(spec, n.bringup, launch, n.moveit, note, control),
    }
    about = f"Gazebo Harmonic + ros2_control bringup of {n.robot} (ROS 2 Jazzy). {note}"
    return {
        **description_files(spec, n, label, info, tops),
        **_package(n.bringup, about, [n.description, *jazzy.BRINGUP_DEPENDS], files, info),
    }


def write_ros_packages(
    spec_path: str | Path,
    out_dir: str | Path,
    *,
    label: str | None = None,
    samples: int = DEFAULT_SAMPLES,
    seed: int = DEFAULT_SEED,
    info: PackageInfo = PackageInfo(),
    target: str = DEFAULT_TARGET,
    force: bool = False,
    packages: PackageLookup | None = None,
) -> tuple[RosPackages, list[Path]]:
    """Load the spec, build the packages in memory, then write them in one atomic swap."""
    path = Path(spec_path)
    resolve_output_dir(out_dir, force=force)  # refuse before the collision sampling
    spec = load_spec(path)
    pkgs = ros_packages(
        spec,
        label=label or path.name,
        samples=samples,
        seed=seed,
        info=info,
        source=str(path),
        target=target,
        packages=packages,
    )
    return pkgs, write_tree_atomic(out_dir, pkgs.files, force=force)
