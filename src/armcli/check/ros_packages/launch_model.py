"""What a launch file starts, as the package rules read it: nodes, includes, processes.

The three readers (Python with `ast`, XML, YAML) produce the same `LaunchDoc`. Values are
only what the file states literally: a string, number or boolean, a package's directory
(`$(find-pkg-share X)`, `get_package_share_directory("X")`, `FindPackageShare("X")`: the
package's directory under DIR, else the URI `package://X`), joined paths, and launch
arguments at their literal defaults (or the value an including launch passes). Anything
else is `None` (a string) or `UNKNOWN` (a parameter value), and the rules stay silent on
it rather than guess.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from armcli.check.ros_packages.files import Problem

PACKAGE_URI = "package://"


class Unknown:
    """A value the file does not state literally (computed, from the environment, ...)."""

    _instance: Unknown | None = None

    def __new__(cls) -> Unknown:
        """The one instance."""
        if cls._instance is None:
            cls._instance = super().__new__(cls)
        return cls._instance

    def __repr__(self) -> str:
        return "<not literal>"


UNKNOWN = Unknown()


@dataclass(frozen=True)
class Where:
    """A place in a file: the file path and its 1-based line."""

    file: str
    line: int | None


@dataclass(frozen=True)
class Description:
    """A robot description a launch (or MoveIt config) loads: a URDF or xacro file.

    With its xacro arguments (only the literal ones; `dropped` names the others).
    """

    file: str  # a path under DIR, or a package:// URI outside it
    args: Mapping[str, str] = field(default_factory=dict)
    dropped: tuple[str, ...] = ()
    where: Where | None = None

    def __post_init__(self) -> None:
        """One spelling per file (`a/./b/../c` is `a/c`), so a file is expanded once."""
        if not self.file.startswith(PACKAGE_URI) and self.file:
            object.__setattr__(self, "file", os.path.normpath(self.file))

    @property
    def key(self) -> tuple[str, tuple[tuple[str, str], ...]]:
        """Identity of one expansion: the file and its arguments."""
        return self.file, tuple(sorted(self.args.items()))


@dataclass(frozen=True)
class Node:
    """A node a launch file starts (launch_ros Node, XML `<node>`, YAML `node:`)."""

    where: Where
    package: str | None
    executable: str | None
    name: str | None = None
    namespace: str | None = None
    params: Mapping[str, object] = field(default_factory=dict)  # inline parameters
    param_lines: Mapping[str, int] = field(default_factory=dict)
    param_files: tuple[str, ...] = ()  # parameter YAML files (paths or package:// URIs)
    unknown_params: bool = False  # a parameter entry that is not literal
    arguments: tuple[str | None, ...] = ()
    remappings: tuple[tuple[str | None, str | None], ...] = ()
    active: bool | None = True  # under the launch's arguments; None: a condition not literal
    description: Description | None = None  # the robot_description it is given
    implied_by: str | None = None  # started by a MoveIt launch generator, not written out

    @property
    def label(self) -> str:
        """`package/executable` as the user wrote it."""
        return f"{self.package or '?'}/{self.executable or '?'}"


@dataclass(frozen=True)
class Include:
    """An included launch file with the arguments passed to it."""

    where: Where
    target: str | None  # path under DIR or package:// URI; None when not literal
    args: Mapping[str, str | None] = field(default_factory=dict)
    active: bool | None = True


@dataclass(frozen=True)
class Process:
    """An ExecuteProcess / `<executable>`: its command tokens (None where not literal)."""

    where: Where
    cmd: tuple[str | None, ...]
    active: bool | None = True


@dataclass(frozen=True)
class MoveItLaunch:
    """A `moveit_configs_utils` launch generator called on a MoveItConfigsBuilder."""

    where: Where
    generator: str  # generate_demo_launch, generate_move_group_launch, ...
    package: str | None  # the MoveIt config package
    robot: str | None


@dataclass(frozen=True)
class LaunchDoc:
    """One launch file read under one set of launch arguments."""

    path: Path
    nodes: tuple[Node, ...] = ()
    includes: tuple[Include, ...] = ()
    processes: tuple[Process, ...] = ()
    moveit: tuple[MoveItLaunch, ...] = ()
    descriptions: tuple[Description, ...] = ()  # every robot description the file loads
    global_params: Mapping[str, object] = field(default_factory=dict)  # SetParameter
    uses: Mapping[str, int] = field(default_factory=dict)  # packages it looks up -> line
    imports: Mapping[str, int] = field(default_factory=dict)  # Python modules -> line
    problems: tuple[Problem, ...] = ()


def package_uri(name: str, rest: str = "") -> str:
    """`package://NAME/rest`: a place in a package that is not under DIR."""
    return f"{PACKAGE_URI}{name}" + (f"/{rest.lstrip('/')}" if rest else "")


def split_package_uri(text: str) -> tuple[str, str] | None:
    """(package, path inside it) of a `package://` URI, else None."""
    if not text.startswith(PACKAGE_URI):
        return None
    name, _, rest = text[len(PACKAGE_URI) :].partition("/")
    return name, rest


def truthy(value: object) -> bool | None:
    """A launch condition's verdict on a literal value (launch's own spelling), else None."""
    if isinstance(value, bool):
        return value
    if isinstance(value, str):
        low = value.strip().lower()
        if low in ("true", "1"):
            return True
        if low in ("false", "0"):
            return False
    if isinstance(value, int):
        return value != 0
    return None
