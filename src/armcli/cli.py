"""The `armcli` command line: a thin typer layer over the library.

This is the only module that prints errors and chooses exit codes. Commands
live in `armcli.commands.*`, each exposing `register(app)`. They are imported only
when run (the composition root is the one place armcli imports its own modules
lazily): `armcli --help` lists them from `COMMANDS` without loading pydantic,
numpy or any command's library, and `armcli build` loads only what build needs.
"""

from __future__ import annotations

import importlib
import sys
import warnings
from typing import Any, TextIO

import click
import typer
import typer.core
import typer.main

from armcli.errors import EXIT_FAILED, ArmcliError, ArmcliWarning
from armcli.io.oneline import one_line
from armcli.io.terminal import say_line

UNSANDBOXED_FLAG = "--trust-xacro-unsandboxed"  # what `--trust-xacro=unsandboxed` becomes
JSON_ERRORS = object()  # the click context's `obj` when errors go to stdout as JSON too

# name -> (module, one-line help for the command list). A test checks that each help
# line is the first line of the command's own docstring.
COMMANDS: dict[str, tuple[str, str]] = {
    "init": (
        "armcli.commands.init",
        "Write an example spec (armcli.yaml), its trajectories and a README; never overwrites.",
    ),
    "import": (
        "armcli.commands.importer",
        "Import a URDF or xacro file into a spec that builds the same URDF back.",
    ),
    "build": (
        "armcli.commands.build",
        "Compile SPEC into the course's xacro set and the expanded URDFs.",
    ),
    "check": (
        "armcli.commands.check",
        "Check robot descriptions for physical sanity; exit 1 on error findings.",
    ),
    "simulate": (
        "armcli.commands.simulate",
        "Simulate the arm tracking a trajectory (Pinocchio ABA under PD control).",
    ),
    "plan": (
        "armcli.commands.plan",
        "Plan a collision-free motion, time it within the limits, certify it, write it.",
    ),
    "place": (
        "armcli.commands.place",
        "Find where the base must stand for the tool to reach a point: least driving first.",
    ),
    "tune": (
        "armcli.commands.tune",
        "Tune PD gains: model-based start, then a seeded search over simulated rollouts.",
    ),
    "ros-package": (
        "armcli.commands.ros",
        "Write ROS 2 packages for SPEC: <name>_description, <name>_bringup, <name>_moveit_config.",
    ),
    "view": (
        "armcli.commands.view",
        "Open a browser 3-D viewer: joint sliders, named poses, replay, motion planning.",
    ),
    "render": (
        "armcli.commands.render",
        "Draw the robot at a pose from two viewpoints into a PNG (headless, no GPU).",
    ),
    "tree": (
        "armcli.commands.tree",
        "Print the kinematic tree: links, and joints with their types and limits.",
    ),
    "export": ("armcli.commands.export", "Export the robot to other simulators' formats."),
    "expand": (
        "armcli.commands.expand",
        "Expand a xacro file like `xacro FILE NAME:=VALUE...`, without running its code.",
    ),
}


class _LazyGroup(typer.core.TyperGroup):
    """Lists commands from COMMANDS and imports a command's module only when it runs."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return list(COMMANDS)

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in COMMANDS:
            return None
        return load_command(cmd_name)

    def invoke(self, ctx: click.Context) -> Any:
        """Click's usage errors (a bad option value) also as JSON on stdout for --format json."""
        try:
            return super().invoke(ctx)
        except click.ClickException as exc:  # typer prints it on stderr and exits
            if ctx.obj is JSON_ERRORS:
                _write_json_error(exc.format_message(), exc.exit_code)
            raise

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(name, help_line) for name, (_, help_line) in COMMANDS.items()]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


def load_command(name: str) -> click.Command:
    """The click command `name`, built from its module's `register(app)`."""
    module = importlib.import_module(COMMANDS[name][0])
    holder = typer.Typer(rich_markup_mode=None, add_completion=False)

    @holder.callback()
    def _group() -> None:  # a callback makes typer build a group even for one command
        """Holder."""

    module.register(holder)
    group: Any = typer.main.get_command(holder)
    command: click.Command = group.commands[name]
    for param in command.params:  # click 8.2.1 says "(env var: 'None')" (click issue #2971)
        if isinstance(param, click.Option) and param.envvar is None:
            param.show_envvar = False
    return command


# Typer escapes "[" for rich's HTML export whenever rich is importable, even with
# rich_markup_mode=None (plain click help), which prints "\\[default: ...]" in --help.
# Plain click help needs no escaping, and nothing else of typer's rich path is used here.
typer.core.HAS_RICH = False

app = typer.Typer(
    cls=_LazyGroup,
    name="armcli",
    help="Typed robot-arm specs -> ROS-ready xacro/URDF, physical sanity checks, and simulation.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # plain click help: no rich/markdown import, units like [rad] kept
)


def _version(value: bool) -> None:
    if value:
        from armcli.commands.version import version_lines  # loads the engine: only here

        sys.stdout.write("".join(f"{line}\n" for line in version_lines()))
        raise typer.Exit()


@app.callback()
def _root(
    debug: bool = typer.Option(False, "--debug", help="Show Python tracebacks for errors."),
    version: bool = typer.Option(
        False,
        "--version",
        callback=_version,
        is_eager=True,
        help="Show the version, the simulator engine (compiled or Python), pin and xacro.",
    ),
) -> None:
    """armcli: robot descriptions without ROS."""


def _print_error(exc: ArmcliError) -> None:
    """One line per problem, labelled by the error's class (never by sniffing its text).

    A newline in a file name or value is escaped (`one_line`): a line of its own could be
    a workflow command such as `::add-mask::` to GitHub Actions, which reads stderr too.
    """
    for line in exc.lines():
        say_line(f"{exc.label}: {line}" if exc.label else line, sys.stderr)


def _json_requested(argv: list[str]) -> bool:
    """`--format json` (or `--format=json`) given to the command: errors go to stdout too."""
    pairs = zip(argv, [*argv[1:], ""], strict=True)
    return "--format=json" in argv or any(a == "--format" and b == "json" for a, b in pairs)


def _write_json_error(reason: str, exit_code: int) -> None:
    """The error as the JSON document a `--format json` caller parses from stdout.

    `status` is "failed" for a negative verdict (exit 1: no plan found, error findings),
    "error" for unusable input (exit 2); nothing was written (`output` null).
    """
    from armcli.io.jsondoc import dumps

    status = "failed" if exit_code == EXIT_FAILED else "error"
    doc = {"status": status, "reason": one_line(reason), "exit_code": exit_code, "output": None}
    sys.stdout.write(dumps(doc))


_show_python_warning = warnings.showwarning


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
) -> None:
    """Our own warnings as `warning: ...` lines (escaped), other warnings as Python shows them."""
    if issubclass(category, ArmcliWarning):
        sys.stderr.write(f"warning: {one_line(str(message))}\n")
    else:
        _show_python_warning(message, category, filename, lineno, file, line)


def _debug_requested(argv: list[str]) -> bool:
    """`--debug` is a root option: it can only appear before the command name."""
    for arg in argv:
        if arg == "--debug":
            return True
        if not arg.startswith("-"):
            return False
    return False


INTERRUPTED = "interrupted (Ctrl-C): stopped; no file was left half-written\n"
EXIT_INTERRUPTED = 130  # 128 + SIGINT; typer's exit for a KeyboardInterrupt it caught


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point: run the app and map exceptions to exit codes.

    Typer (standalone mode) handles usage errors itself (exit 2); everything
    armcli raises on purpose is an ArmcliError carrying its own exit code.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    # `--trust-xacro=unsandboxed` is the documented spelling; a bool flag cannot take a value
    args = [UNSANDBOXED_FLAG if a == "--trust-xacro=unsandboxed" else a for a in args]
    debug = _debug_requested(args)
    warnings.showwarning = _show_warning
    status = None
    if sys.stderr.isatty():  # at a terminal: one line if the command stays silent
        from armcli.commands.status import start_status  # a command module: loaded on use

        status = start_status(args)
    try:
        app(args=args, prog_name="armcli", obj=JSON_ERRORS if _json_requested(args) else None)
    except SystemExit as exc:  # typer turns Ctrl-C into a silent exit 130: say it once
        if exc.code == EXIT_INTERRUPTED:
            sys.stderr.write(INTERRUPTED)
        raise
    except KeyboardInterrupt:
        sys.stderr.write(INTERRUPTED)
        raise SystemExit(EXIT_INTERRUPTED) from None
    except ArmcliError as exc:
        if debug:
            raise
        _print_error(exc)
        if _json_requested(args) and not exc.reported:
            _write_json_error("; ".join(exc.lines()), exc.exit_code)
        raise SystemExit(exc.exit_code) from None
    except Exception as exc:  # a bug: say so in one line unless --debug
        if debug:
            raise
        sys.stderr.write(
            f"internal error: {type(exc).__name__}: {one_line(str(exc))} "
            "(rerun with --debug for a traceback)\n"
        )
        raise SystemExit(EXIT_FAILED) from None
    finally:
        if status is not None:
            status.stop()


if __name__ == "__main__":
    main()
