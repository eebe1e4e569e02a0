"""The one option group of every command that reads a robot: declared once, parsed once.

`armcli check|tree|view|render|expand|import|export mjcf|simulate|plan ROBOT NAME:=VALUE ...`
all take the robot file, xacro's own `NAME:=VALUE` arguments after it, `--env VAR=VALUE`
for `$(env)`/`$(optenv)`, `--package-dir NAME=PATH` for `$(find NAME)` and
`package://NAME/` (see armcli.io.packages for the rest of the lookup) and
`--trust-xacro[-unsandboxed]`. A command declares a parameter `robot: RobotInput` and
the decorator `robot_options(...)` adds these options to its signature and hands it the
parsed `armcli.urdf.source.RobotInput`, so a malformed one is refused, with its flag
named, before the command runs (FastAPI's dependencies, for typer). What the expansion
used is printed to stderr as `note:` lines, the same way by every command.
"""

from __future__ import annotations

import functools
import inspect
import sys
import types
import typing
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, Literal, TypeVar

import typer

from armcli.defaults import SPEC_HELP
from armcli.errors import InputError
from armcli.io.oneline import one_line
from armcli.io.packages import PackageLookup, parse_package_dirs
from armcli.io.terminal import say
from armcli.xacro.args import ARGS_HELP, ENV_HELP, XacroInputs, is_arg, parse_args, parse_env
from armcli.xacro.trust import TRUST_XACRO_HELP, UNSANDBOXED_HELP, trust_mode

if typing.TYPE_CHECKING:
    from armcli.urdf.source import RobotInput

KEYWORD_ONLY = inspect.Parameter.KEYWORD_ONLY  # typer passes every parameter by name
F = TypeVar("F", bound=Callable[..., Any])
Kind = Literal["robot", "spec", "file", "paths"]  # what the positional argument names

ROBOT_HELP = (
    "Robot spec YAML, URDF file, or xacro file (expanded in safe mode); "
    "default: ./armcli.yaml, else the spec in specs/."
)
PACKAGE_DIR_HELP = (
    "NAME=PATH: package NAME is at PATH, for $(find NAME) and package://NAME/ (repeatable); "
    "otherwise AMENT_PREFIX_PATH, ROS_PACKAGE_PATH and the package enclosing the file."
)
PATHS_HELP = (
    "URDF or xacro files, spec YAMLs (built in memory) or directories (every *.urdf); "
    "default: ./armcli.yaml, else the spec in specs/. NAME:=VALUE: xacro arguments."
)
FILE_HELP = "URDF or xacro file."
_POSITIONAL = {  # kind -> (metavar, required, help)
    "robot": ("ROBOT", False, ROBOT_HELP),
    "spec": ("SPEC", False, SPEC_HELP),
    "file": ("FILE", True, FILE_HELP),
}
_GROUP = ("robot_file", "xacro_args", "package_dir", "env", "trust_xacro", "unsandboxed")


def _parameters(
    kind: Kind, help: str | None, xacro: bool, packages: bool
) -> tuple[list[Any], list[Any]]:
    """The group's parameters: (the positional ones, the options), typer-declared."""

    def param(name: str, annotation: Any, default: Any) -> inspect.Parameter:
        return inspect.Parameter(name, KEYWORD_ONLY, annotation=annotation, default=default)

    if kind == "paths":
        metavar = "[PATHS]... [NAME:=VALUE]..."
        text = help or PATHS_HELP
        first = typer.Argument(None, metavar=metavar, show_default=False, help=text)
        positional = [param("robot_file", list[str] | None, first)]
    else:
        name, required, default_help = _POSITIONAL[kind]
        metavar = name if required else f"[{name}]"
        text = help or default_help
        first = typer.Argument(
            ... if required else None, metavar=metavar, show_default=False, help=text
        )
        positional = [param("robot_file", Path | None, first)]
        if xacro:
            rest = typer.Argument(
                None, metavar="[NAME:=VALUE]...", show_default=False, help=ARGS_HELP
            )
            positional.append(param("xacro_args", list[str] | None, rest))
    pkg = typer.Option([], "--package-dir", metavar="NAME=PATH", help=PACKAGE_DIR_HELP)
    options = [param("package_dir", list[str], pkg)] if packages or xacro else []  # xacro: both
    if xacro:
        options += [
            param("env", list[str], typer.Option([], "--env", metavar="VAR=VALUE", help=ENV_HELP)),
            param("trust_xacro", bool, typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP)),
            param(
                "unsandboxed",
                bool,
                typer.Option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
            ),
        ]
    return positional, options


def robot_options(
    kind: Kind = "robot", *, help: str | None = None, xacro: bool = True, packages: bool = True
) -> Callable[[F], F]:
    """Give the command's `robot: RobotInput` parameter from the shared options.

    `kind`: the positional argument (`robot` optional ROBOT, `spec` optional SPEC,
    `file` a required FILE, `paths` check's files and directories); `xacro=False`: a
    spec-only command (ros-package), which takes `--package-dir` alone; with
    `packages=False` too (build, tune), the spec argument alone.
    """

    def decorate(fn: F) -> F:
        hints = _hints(fn)
        own = [
            p.replace(kind=KEYWORD_ONLY, annotation=hints.get(p.name, p.annotation))
            for p in inspect.signature(fn).parameters.values()
            if p.name != "robot"
        ]
        positional, options = _parameters(kind, help, xacro, packages)

        @functools.wraps(fn)
        def command(**kwargs: Any) -> Any:
            group = {name: kwargs.pop(name, None) for name in _GROUP}
            return fn(robot=parse(kind, **group), **kwargs)

        params = [*positional, *own, *options]
        command.__signature__ = inspect.Signature(params)  # type: ignore[attr-defined]
        command.__annotations__ = {p.name: p.annotation for p in params}
        del command.__wrapped__  # typer reads the signature above, not fn's
        return typing.cast(F, command)

    return decorate


def _hints(fn: Callable[..., Any]) -> dict[str, Any]:
    """`fn`'s annotations evaluated, but `robot`'s: RobotInput is imported on use (light --help)."""
    holder = types.SimpleNamespace(
        __annotations__={k: v for k, v in fn.__annotations__.items() if k != "robot"}
    )
    return typing.get_type_hints(holder, globalns=fn.__globals__)


def parse(
    kind: Kind,
    *,
    robot_file: Path | list[str] | None = None,
    xacro_args: list[str] | None = None,
    package_dir: list[str] | None = None,
    env: list[str] | None = None,
    trust_xacro: bool | None = None,
    unsandboxed: bool | None = None,
) -> RobotInput:
    """The group's values as one RobotInput; InputError naming the malformed option."""
    from armcli.urdf.source import RobotInput  # lxml: only when a command runs

    if kind == "paths":
        paths, args = _split_paths(robot_file if isinstance(robot_file, list) else [])
    else:
        path, args = _split_robot(robot_file if isinstance(robot_file, Path) else None, xacro_args)
        if path is None and kind == "file":
            raise InputError("give the file before its NAME:=VALUE arguments", field="FILE")
        paths = [] if path is None else [path]
    inputs = XacroInputs(
        args=parse_args(args),
        env=parse_env(env or []),
        packages=PackageLookup(parse_package_dirs(list(package_dir or []))),
    )
    trust = trust_mode(bool(trust_xacro), bool(unsandboxed))
    return RobotInput(paths=tuple(paths), xacro=inputs, trust=trust)


def _split_robot(robot: Path | None, args: list[str] | None) -> tuple[Path | None, list[str]]:
    """The robot file and the xacro arguments, when click put the first argument in ROBOT.

    `armcli tree name:=x` (no file: the spec is found) assigns `name:=x` to the ROBOT
    argument; like xacro, any token with `:=` is an argument.
    """
    rest = list(args or [])
    if robot is not None and is_arg(str(robot)):
        return None, [str(robot), *rest]
    stray = [a for a in rest if not is_arg(a)]
    if stray:
        raise InputError(
            f"unexpected argument {stray[0]!r}: after the robot file only xacro arguments "
            "NAME:=VALUE may follow",
            field="[NAME:=VALUE]...",
        )
    return robot, rest


def _split_paths(tokens: Iterable[str]) -> tuple[list[Path], list[str]]:
    """`check`'s arguments: files (or directories) and xacro `NAME:=VALUE` arguments."""
    paths: list[Path] = []
    args: list[str] = []
    for t in tokens:
        if is_arg(t):
            args.append(t)
        else:
            paths.append(Path(t))
    return paths, args


def write_notes(notes: Iterable[str], file: str | None = None) -> None:
    """Print what reading a robot file reported (`note: ...`, `warning: ...`) to stderr.

    `file` names the robot file when several are read (check). File names and the
    values in notes (xacro argument defaults) come from the input: a newline or carriage
    return in them would start a line of its own, a workflow command to GitHub Actions
    (`one_line`), so each note stays one line.
    """
    for line in notes:
        label, _, text = line.partition(": ")
        shown = f"{label}: {file}: {text}" if file else line
        say(one_line(shown), sys.stderr)  # one line in a log; wrapped at a terminal
