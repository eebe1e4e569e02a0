"""What the package rules share, and the findings so far.

The packages, their launch runs, MoveIt configs, robot descriptions, controllers files
and the distro.

Each rule is a function of a `PackageContext` (run.py's `RULE_FAMILIES`). The context
answers the questions several rules ask: which robot descriptions a launch loads, which
controllers file a description's Gazebo plugin or a launch's `ros2_control_node` reads,
which robot a MoveIt config plans for. Findings point at the file that must change: a
launch file's line, a YAML key's line, a package.xml, or (for an element of a xacro
expansion) the file and line the element was written on.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from armcli.check.findings import Finding, Value
from armcli.check.ros_packages.distro import Distro
from armcli.check.ros_packages.files import Problem
from armcli.check.ros_packages.launch_model import Description, split_package_uri
from armcli.check.ros_packages.launches import Run
from armcli.check.ros_packages.moveit import MoveItConfig
from armcli.check.ros_packages.params import ControllerFile, controller_file
from armcli.check.ros_packages.workspace import Workspace
from armcli.check.rules import RULES
from armcli.errors import InputError
from armcli.io.yaml import YamlDoc, loads_yaml
from armcli.urdf.doc import Urdf
from armcli.urdf.srdf import Srdf
from armcli.xacro.lines import Origin

if TYPE_CHECKING:
    from armcli.robot.model import Robot
    from armcli.spec.model import RobotSpec

GAZEBO_CONTROL_PLUGINS = (
    "gz_ros2_control-system",
    "ign_ros2_control-system",
    "libgz_ros2_control-system.so",
    "libign_ros2_control-system.so",
    "libgazebo_ros2_control.so",
)


@dataclass
class PackageContext:
    """One `check DIR` over ROS packages: inputs, derived facts and findings."""

    ws: Workspace
    runs: list[Run]
    moveit: list[MoveItConfig]
    robots: Mapping[tuple[object, ...], Urdf]  # Description.key -> its URDF
    distro: Distro
    spec: RobotSpec | None = None
    complete: bool = True  # every robot description named could be read
    findings: list[Finding] = field(default_factory=list)
    problems: dict[str, Problem] = field(default_factory=dict)
    srdfs: dict[Path, tuple[Srdf, dict[int, Origin]] | None] = field(default_factory=dict)
    _yaml: dict[Path, YamlDoc | None] = field(default_factory=dict)
    _models: dict[int, Robot | None] = field(default_factory=dict)

    def add(
        self,
        rule: str,
        file: str | Path,
        line: int | None,
        message: str,
        fix: Mapping[str, Value] | None = None,
        /,
        **values: Value,
    ) -> None:
        """Record a finding of `rule` in `file` at `line` (severity and hint from RULES)."""
        r = RULES[rule]
        self.findings.append(
            Finding(rule, r.severity, str(file), line, message, values, r.hint, dict(fix or {}))
        )

    def add_in(
        self,
        rule: str,
        urdf: Urdf,
        line: int | None,
        message: str,
        fix: Mapping[str, Value] | None = None,
        /,
        **values: Value,
    ) -> None:
        """A finding on an element of a robot description (its xacro origin kept)."""
        r = RULES[rule]
        origin = urdf.origins.get(line) if line else None
        self.findings.append(
            Finding(
                rule,
                r.severity,
                urdf.source,
                line,
                message,
                values,
                r.hint,
                dict(fix or {}),
                origin=origin,
            )
        )

    def yaml(self, path: Path) -> YamlDoc | None:
        """A YAML file under DIR, read once; an unreadable one is recorded as a problem."""
        if path not in self._yaml:
            try:
                self._yaml[path] = self.ws.jail.yaml(path)
            except InputError as exc:
                self.problems.setdefault(str(path), Problem.of(exc, path))
                self._yaml[path] = None
        return self._yaml[path]

    def controllers(self, path: Path) -> ControllerFile | None:
        """The controllers file at `path`, or None when it is not one (or unreadable)."""
        doc = self.yaml(path) if self.local(str(path)) else None
        return controller_file(path, doc) if doc is not None else None

    def local(self, file: str) -> Path | None:
        """A path under DIR that is a file of a package, else None (package:// URIs too)."""
        if split_package_uri(file) is not None:
            return None
        p = Path(file)
        return p if p.is_file() and self.ws.jail.allows(p) else None

    def urdf(self, d: Description) -> Urdf | None:
        """The expansion of a robot description, when it could be read."""
        return self.robots.get(d.key)

    def urdfs(self, descriptions: Iterable[Description]) -> list[Urdf]:
        """The readable expansions among `descriptions`, without repeats."""
        out: list[Urdf] = []
        for d in descriptions:
            u = self.urdf(d)
            if u is not None and all(u is not v for v in out):
                out.append(u)
        return out

    def model(self, urdf: Urdf) -> Robot | None:
        """The Pinocchio robot of a description, loaded once (None when it does not load)."""
        key = id(urdf)
        if key not in self._models:
            from armcli.errors import ArmcliError
            from armcli.robot.model import Robot

            try:
                self._models[key] = Robot.load(urdf, strict=False)
            except (ArmcliError, ValueError, RuntimeError):
                self._models[key] = None
        return self._models[key]

    def gazebo_controllers(self, urdf: Urdf) -> list[Path]:
        """The controllers files a description's Gazebo ros2_control plugin loads."""
        out = []
        for p in urdf.plugins:
            if (p.filename or "").rsplit("/", 1)[-1] in GAZEBO_CONTROL_PLUGINS:
                for text in (p.params.get("parameters") or "").split():
                    local = self.local(text)
                    if local is not None:
                        out.append(local)
        return out

    def run_controllers(self, run: Run) -> list[Path]:
        """Controllers files a launch run loads.

        Its nodes' parameter files and its robot descriptions' Gazebo plugins.
        """
        out: list[Path] = []
        for n in run.nodes:
            out += [p for f in n.param_files if (p := self.local(f)) is not None]
        for u in self.urdfs(run.descriptions):
            out += self.gazebo_controllers(u)
        return list(dict.fromkeys(out))

    def owners(self) -> dict[Path, list[Urdf]]:
        """Controllers file -> the robots it drives.

        By its description's Gazebo plugin, the launch starting ros2_control_node with
        it, its MoveIt config, else (when every robot was read) the robots that share a
        joint with it.
        """
        out: dict[Path, list[Urdf]] = {}
        for urdf in self.robots.values():
            for path in self.gazebo_controllers(urdf):
                out.setdefault(path, []).append(urdf)
        for run in self.runs:
            robots = self.urdfs(run.descriptions)
            for n in run.nodes:
                if n.package == "controller_manager" and n.executable == "ros2_control_node":
                    for f in n.param_files:
                        local = self.local(f)
                        if local is not None and robots:
                            out.setdefault(local, []).extend(robots)
        for cfg in self.moveit:
            robot = self.moveit_urdf(cfg)
            if cfg.ros2_controllers is not None and robot is not None:
                out.setdefault(cfg.ros2_controllers, []).append(robot)
        if self.complete:  # guessing the robot is only safe when every robot was read
            for path in self.all_controller_files():
                if path in out:
                    continue
                cf = self.controllers(path)
                named = {j for c in cf.controllers.values() for j in c.joints} if cf else set()
                sharing = [u for u in self.robots.values() if named & {j.name for j in u.joints}]
                if sharing:
                    out[path] = sharing
        return out

    def moveit_urdf(self, cfg: MoveItConfig) -> Urdf | None:
        """The robot a MoveIt config plans for."""
        return self.urdf(cfg.description) if cfg.description is not None else None

    def all_controller_files(self) -> list[Path]:
        """Every YAML file of the packages that declares ros2_control controllers.

        A YAML file no rule names is read quietly: one that armcli's safe reader refuses
        (anchors, duplicate keys) is skipped here and reported only where a launch, a
        plugin or a MoveIt config uses it.
        """
        out = []
        for pkg in self.ws.packages.values():
            if pkg.ros1:
                continue
            for f in pkg.files:
                if f.suffix not in (".yaml", ".yml"):
                    continue
                read = f in self._yaml
                if (not read and self._quiet(f)) or (read and self.controllers(f) is not None):
                    out.append(f)
        return out

    def _quiet(self, path: Path) -> bool:
        """Whether `path` is a controllers file, reading it without recording problems."""
        try:
            text = self.ws.jail.text(path, "YAML file")
            if "ros__parameters" not in text:
                return False
            doc = loads_yaml(text, str(path), merge_duplicates=True)
        except InputError:
            return False
        self._yaml[path] = doc
        return controller_file(path, doc) is not None
