"""The `armcli` command line: a thin typer layer over the library.

This is the only module that prints errors and chooses exit codes. Commands
live in `armcli.commands.*`, each exposing `register(app)`; they import heavy
libraries (pinocchio, xacro, matplotlib, viser) inside the command body so
that `armcli --help` stays fast.
"""

from __future__ import annotations

import os
import sys

import typer

from armcli.errors import EXIT_FAILED, ArmcliError

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
        from armcli.about import version_lines

        sys.stdout.write("".join(f"{line}\n" for line in version_lines()))
        raise typer.Exit()


@app.callback()
def _root(
    debug: bool = typer.Option(False, "--debug", help="Show Python tracebacks for errors."),
    version: bool = typer.Option(
        False,
        "--version",
        is_eager=True,
        callback=_version,
        help="Show the version, the simulator engine (compiled or Python), pin and xacro.",
    ),
) -> None:
    """armcli: robot descriptions without ROS."""
    if debug:
        os.environ["ARMCLI_DEBUG"] = "1"


def _register() -> None:
    from armcli.commands import build, check, init, ros, simulate, view

    for module in (init, build, check, simulate, ros, view):
        module.register(app)


_register()


def _err(line: str) -> None:
    sys.stderr.write(
        f"error: {line}\n" if not line.startswith(("stale:", "error")) else line + "\n"
    )


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point: run the app and map exceptions to exit codes.

    Typer (standalone mode) handles usage errors itself (exit 2); everything
    armcli raises on purpose is an ArmcliError carrying its own exit code.
    """
    try:
        app(args=argv, prog_name="armcli")
    except ArmcliError as exc:
        if os.environ.get("ARMCLI_DEBUG"):
            raise
        for line in exc.lines():
            _err(line)
        raise SystemExit(exc.exit_code) from None
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        raise SystemExit(130) from None
    except Exception as exc:  # a bug: say so in one line unless --debug
        if os.environ.get("ARMCLI_DEBUG"):
            raise
        sys.stderr.write(
            f"internal error: {type(exc).__name__}: {exc} (rerun with --debug for a traceback)\n"
        )
        raise SystemExit(EXIT_FAILED) from None


if __name__ == "__main__":
    main()
