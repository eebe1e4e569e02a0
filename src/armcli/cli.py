"""The `armcli` command line: a thin typer layer over the library.

This is the only module that prints errors and chooses exit codes. Commands
live in `armcli.commands.*`, each exposing `register(app)`; the library modules
they call import heavy libraries (pinocchio, xacro, matplotlib, viser) inside
functions, so that `armcli --help` stays fast.
"""

from __future__ import annotations

import sys

import typer
import typer.core

import armcli
from armcli.commands import build, check, render, ros, simulate, tree, view
from armcli.errors import EXIT_FAILED, ArmcliError

UNSANDBOXED_FLAG = "--trust-xacro-unsandboxed"  # what `--trust-xacro=unsandboxed` becomes

# Typer escapes "[" for rich's HTML export whenever rich is importable, even with
# rich_markup_mode=None (plain click help), which prints "\\[default: ...]" in --help.
# Plain click help needs no escaping, and nothing else of typer's rich path is used here.
typer.core.HAS_RICH = False

app = typer.Typer(
    name="armcli",
    help="Typed robot-arm specs -> ROS-ready xacro/URDF, physical sanity checks, and simulation.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # plain click help: no rich/markdown import, units like [rad] kept
)


def _version(value: bool) -> None:
    if value:
        sys.stdout.write(f"armcli {armcli.__version__}\n")
        raise typer.Exit()


@app.callback()
def _root(
    debug: bool = typer.Option(False, "--debug", help="Show Python tracebacks for errors."),
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    """armcli: robot descriptions without ROS."""


for _module in (build, check, simulate, ros, view, render, tree):
    _module.register(app)


def _print_error(exc: ArmcliError) -> None:
    """One line per problem, labelled by the error's class (never by sniffing its text)."""
    for line in exc.lines():
        sys.stderr.write(f"{exc.label}: {line}\n" if exc.label else f"{line}\n")


def _debug_requested(argv: list[str]) -> bool:
    """`--debug` is a root option: it can only appear before the command name."""
    for arg in argv:
        if arg == "--debug":
            return True
        if not arg.startswith("-"):
            return False
    return False


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point: run the app and map exceptions to exit codes.

    Typer (standalone mode) handles usage errors itself (exit 2); everything
    armcli raises on purpose is an ArmcliError carrying its own exit code.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    # `--trust-xacro=unsandboxed` is the documented spelling; a bool flag cannot take a value
    args = [UNSANDBOXED_FLAG if a == "--trust-xacro=unsandboxed" else a for a in args]
    debug = _debug_requested(args)
    try:
        app(args=args, prog_name="armcli")
    except ArmcliError as exc:
        if debug:
            raise
        _print_error(exc)
        raise SystemExit(exc.exit_code) from None
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        raise SystemExit(130) from None
    except Exception as exc:  # a bug: say so in one line unless --debug
        if debug:
            raise
        sys.stderr.write(
            f"internal error: {type(exc).__name__}: {exc} (rerun with --debug for a traceback)\n"
        )
        raise SystemExit(EXIT_FAILED) from None


if __name__ == "__main__":
    main()
