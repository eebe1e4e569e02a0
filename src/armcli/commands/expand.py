"""`armcli expand`: xacro's command line, in safe mode (no code from the file runs)."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from armcli.commands.xacro_inputs import (
    args_argument,
    env_option,
    package_dir_option,
    split_robot,
    write_notes,
    xacro_inputs,
)
from armcli.errors import InputError
from armcli.io.files import write_file_atomic
from armcli.io.oneline import one_line
from armcli.io.outdir import check_output_file
from armcli.xacro.trust import TRUST_XACRO_HELP, UNSANDBOXED_HELP, trust_mode


def expand_cmd(
    file: Path = typer.Argument(..., show_default=False, help="The xacro file to expand."),
    args: list[str] = args_argument(),
    out: Path = typer.Option(
        None, "-o", "--out", show_default=False, help="Write the URDF here (default: stdout)."
    ),
    env: list[str] = env_option(),
    package_dir: list[str] = package_dir_option(),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
    unsandboxed: bool = typer.Option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
) -> None:
    """Expand a xacro file like `xacro FILE NAME:=VALUE...`, without running its code.

    The arguments used and the defaults taken are reported on stderr.
    """
    from armcli.urdf.source import expand_xacro  # on use: `--help` imports no numpy or lxml

    robot, tokens = split_robot(file, args)
    if robot is None:
        raise InputError("give the xacro file before its NAME:=VALUE arguments", field="FILE")
    if out is not None:
        check_output_file(out, "--out", [robot])  # before any work; never over the input
    inputs = xacro_inputs(tokens, env, package_dir)
    xml, used = expand_xacro(robot, trust_xacro=trust_mode(trust_xacro, unsandboxed), inputs=inputs)
    write_notes(used.notes())
    if out is None:
        sys.stdout.buffer.write(xml)
        sys.stdout.flush()
        return
    write_file_atomic(out, xml)
    sys.stderr.write(one_line(f"wrote {out}") + "\n")


def register(app: typer.Typer) -> None:
    """Add `armcli expand` to the app."""
    app.command("expand")(expand_cmd)
