"""What every command that reads a robot file shares for xacro: arguments, --env, --package-dir.

`armcli check|tree|view|render|export mjcf FILE NAME:=VALUE ...` and
`armcli simulate --urdf FILE NAME:=VALUE ...` take xacro's own `NAME:=VALUE`
arguments after the file, `--env VAR=VALUE` for `$(env)`/`$(optenv)` and
`--package-dir NAME=PATH` for `$(find NAME)` and `package://NAME/` (see
armcli.io.packages for the rest of the lookup). What the expansion used is
printed to stderr as `note:` lines, the same way by every command.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import typer

from armcli.errors import InputError
from armcli.io.oneline import one_line
from armcli.io.packages import PackageLookup, parse_package_dirs
from armcli.io.terminal import say
from armcli.xacro.args import ARGS_HELP, ENV_HELP, XacroInputs, is_arg, parse_args, parse_env

PACKAGE_DIR_HELP = (
    "NAME=PATH: package NAME is at PATH, for $(find NAME) and package://NAME/ (repeatable); "
    "otherwise AMENT_PREFIX_PATH, ROS_PACKAGE_PATH and the package enclosing the file."
)


def args_argument() -> Any:
    """The trailing `[NAME:=VALUE]...` argument."""
    return typer.Argument(None, metavar="[NAME:=VALUE]...", show_default=False, help=ARGS_HELP)


def env_option() -> Any:
    """`--env VAR=VALUE` (repeatable)."""
    return typer.Option([], "--env", metavar="VAR=VALUE", help=ENV_HELP)


def package_dir_option() -> Any:
    """`--package-dir NAME=PATH` (repeatable)."""
    return typer.Option([], "--package-dir", metavar="NAME=PATH", help=PACKAGE_DIR_HELP)


def xacro_inputs(
    args: Iterable[str], env: Iterable[str], package_dir: Iterable[str]
) -> XacroInputs:
    """The parsed options as one XacroInputs; InputError naming a malformed one."""
    return XacroInputs(
        args=parse_args(args),
        env=parse_env(env),
        packages=PackageLookup(parse_package_dirs(list(package_dir))),
    )


def split_robot(robot: Path | None, args: list[str] | None) -> tuple[Path | None, list[str]]:
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


def split_paths(tokens: Iterable[str]) -> tuple[list[Path], list[str]]:
    """`check`'s arguments: files (or directories) and xacro `NAME:=VALUE` arguments."""
    paths: list[Path] = []
    args: list[str] = []
    for t in tokens:
        (args if is_arg(t) else paths).append(t if is_arg(t) else Path(t))  # type: ignore[arg-type]
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
