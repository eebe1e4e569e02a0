"""MoveIt config packages under DIR: their URDF, SRDF, controllers and start tolerance.

A package is a MoveIt config when it holds an SRDF (`*.srdf`, `*.srdf.xacro`) next to a
`.setup_assistant` or MoveIt's YAML (`moveit_controllers.yaml`, `kinematics.yaml`). Its
robot description is the one `.setup_assistant` names (`urdf`/`URDF`: package and
relative path, with `xacro_args`), else `config/<robot>.urdf.xacro` as MoveItConfigsBuilder
looks for it. `trajectory_execution.allowed_start_tolerance` is read where MoveIt reads
it (moveit_controllers.yaml), 0.01 rad when absent (MoveIt's default).
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass
from pathlib import Path

from armcli.check.ros_packages.files import Problem
from armcli.check.ros_packages.launch_model import Description, Where
from armcli.check.ros_packages.workspace import Package, Workspace
from armcli.errors import InputError
from armcli.io.yaml import YamlDoc

START_TOLERANCE = 0.01  # [rad] MoveIt's trajectory_execution.allowed_start_tolerance default
SETUP_ASSISTANT = ".setup_assistant"
MOVEIT_YAML = ("moveit_controllers.yaml", "kinematics.yaml", "joint_limits.yaml")


@dataclass(frozen=True)
class Tolerance:
    """MoveIt's allowed start tolerance and where it is written (None: its default)."""

    value: float
    where: Where | None


@dataclass(frozen=True)
class MoveItConfig:
    """One MoveIt config package."""

    package: Package
    srdf: Path | None
    description: Description | None  # the URDF the config loads
    controllers: Path | None  # moveit_controllers.yaml
    ros2_controllers: Path | None
    joint_limits: Path | None
    initial_positions: Path | None
    tolerance: Tolerance
    controller_names: tuple[str, ...] = ()  # moveit_simple_controller_manager's


def _named(pkg: Package, name: str) -> Path | None:
    found = [f for f in pkg.files if f.name == name]
    return min(found, key=lambda f: len(f.parts)) if found else None


def is_moveit_config(pkg: Package) -> bool:
    """An SRDF beside a .setup_assistant or MoveIt's own YAML files."""
    names = {f.name for f in pkg.files}
    srdf = any(n.endswith((".srdf", ".srdf.xacro")) for n in names)
    return srdf and (SETUP_ASSISTANT in names or any(n in names for n in MOVEIT_YAML))


def moveit_configs(ws: Workspace) -> tuple[list[MoveItConfig], list[Problem]]:
    """Every MoveIt config package under DIR; its unreadable files as problems."""
    configs: list[MoveItConfig] = []
    problems: list[Problem] = []
    for pkg in ws.packages.values():
        if pkg.ros1 or not is_moveit_config(pkg):
            continue
        assistant = _setup_assistant(ws, pkg, problems)
        srdfs = sorted(
            (f for f in pkg.files if f.name.endswith((".srdf", ".srdf.xacro"))),
            key=lambda f: (len(f.parts), str(f)),
        )
        srdf = assistant[1] if assistant[1] is not None else srdfs[0]
        controllers = _named(pkg, "moveit_controllers.yaml")
        tolerance, names = _execution(ws, controllers, problems)
        description = assistant[0] or _builder_default(pkg, srdf)
        configs.append(
            MoveItConfig(
                pkg,
                srdf,
                description,
                controllers,
                _named(pkg, "ros2_controllers.yaml"),
                _named(pkg, "joint_limits.yaml"),
                _named(pkg, "initial_positions.yaml"),
                tolerance,
                names,
            )
        )
    return configs, problems


def _setup_assistant(
    ws: Workspace, pkg: Package, problems: list[Problem]
) -> tuple[Description | None, Path | None]:
    """The URDF (with xacro arguments) and SRDF a `.setup_assistant` names."""
    path = pkg.root / SETUP_ASSISTANT
    if path not in pkg.files:
        return None, None
    try:
        doc = ws.jail.yaml(path, ".setup_assistant")
    except InputError as exc:
        problems.append(Problem.of(exc, path))
        return None, None
    cfg = doc.data.get("moveit_setup_assistant_config") if isinstance(doc.data, dict) else None
    if not isinstance(cfg, dict):
        return None, None
    urdf = cfg.get("urdf", cfg.get("URDF"))
    srdf = cfg.get("srdf", cfg.get("SRDF"))
    description = None
    if isinstance(urdf, dict) and isinstance(urdf.get("relative_path"), str):
        root = ws.find(str(urdf.get("package", pkg.name))) or pkg.root
        key = "urdf" if "urdf" in cfg else "URDF"
        args = _xacro_args(urdf.get("xacro_args"))
        description = Description(
            str(root / urdf["relative_path"]),
            args,
            (),
            Where(str(path), doc.line_of(("moveit_setup_assistant_config", key))),
        )
    srdf_path = None
    if isinstance(srdf, dict) and isinstance(srdf.get("relative_path"), str):
        candidate = pkg.root / srdf["relative_path"]
        srdf_path = candidate if candidate in pkg.files else None
    return description, srdf_path


def _xacro_args(text: object) -> dict[str, str]:
    if not isinstance(text, str) or not text.strip():
        return {}
    try:
        tokens = shlex.split(text)
    except ValueError:
        return {}
    return dict(t.split(":=", 1) for t in tokens if ":=" in t)


def _builder_default(pkg: Package, srdf: Path) -> Description | None:
    """MoveItConfigsBuilder's default URDF: config/<robot>.urdf.xacro (robot: the SRDF's stem)."""
    robot = srdf.name.split(".")[0]
    path = pkg.root / "config" / f"{robot}.urdf.xacro"
    return Description(str(path)) if path in pkg.files else None


def _execution(
    ws: Workspace, path: Path | None, problems: list[Problem]
) -> tuple[Tolerance, tuple[str, ...]]:
    """allowed_start_tolerance and the controller names of moveit_controllers.yaml."""
    default = Tolerance(START_TOLERANCE, None)
    if path is None:
        return default, ()
    try:
        doc = ws.jail.yaml(path, "moveit_controllers.yaml")
    except InputError as exc:
        problems.append(Problem.of(exc, path))
        return default, ()
    data = doc.data if isinstance(doc.data, dict) else {}
    names = _controller_names(data)
    te = data.get("trajectory_execution")
    if isinstance(te, dict):
        value = te.get("allowed_start_tolerance")
        if isinstance(value, int | float) and not isinstance(value, bool):
            at = ("trajectory_execution", "allowed_start_tolerance")
            return Tolerance(float(value), Where(str(path), doc.line_of(at))), names
    return default, names


def _controller_names(data: dict[str, object]) -> tuple[str, ...]:
    manager = data.get("moveit_simple_controller_manager")
    names = manager.get("controller_names") if isinstance(manager, dict) else None
    return tuple(n for n in names if isinstance(n, str)) if isinstance(names, list) else ()


def moveit_controller_joints(doc: YamlDoc) -> list[tuple[str, str, int | None]]:
    """(controller, joint, line) of every joint moveit_controllers.yaml names."""
    out: list[tuple[str, str, int | None]] = []
    data = doc.data if isinstance(doc.data, dict) else {}
    manager = data.get("moveit_simple_controller_manager")
    if not isinstance(manager, dict):
        return out
    for name, body in manager.items():
        joints = body.get("joints") if isinstance(body, dict) else None
        for i, j in enumerate(joints if isinstance(joints, list) else []):
            if isinstance(j, str):
                key = ("moveit_simple_controller_manager", name, "joints", i)
                out.append((str(name), j, doc.line_of(key)))
    return out
