"""`armcli expand`: xacro's command line, in safe mode (no code from the file runs)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.robot_input import robot_options, write_notes
from armcli.io.files import write_file_atomic
from armcli.io.outdir import check_output_file, existing, wrote
from armcli.io.terminal import say_line
from armcli.io.workflow import no_workflow_commands

if TYPE_CHECKING:
    from armcli.urdf.source import RobotInput


@robot_options("file", help="The xacro file to expand.")
def expand_cmd(
    robot: RobotInput,
    out: Path = typer.Option(
        None, "-o", "--out", show_default=False, help="Write the URDF here (default: stdout)."
    ),
) -> None:
    """Expand a xacro file like `xacro FILE NAME:=VALUE...`, without running its code.

    The arguments used and the defaults taken are reported on stderr.
    """
    from armcli.urdf.source import expand_xacro  # on use: `--help` imports no numpy or lxml

    path = robot.file()
    if out is not None:
        check_output_file(out, "--out", [path])  # before any work; never over the input
    before = existing(out)
    xml, used = expand_xacro(path, trust_xacro=robot.trust, inputs=robot.xacro)
    xml = no_workflow_commands(xml)  # no line of it a CI log reads as a command (issue 42)
    write_notes(used.notes())
    if out is None:
        sys.stdout.buffer.write(xml)
        sys.stdout.flush()
        return
    write_file_atomic(out, xml)
    say_line(wrote(out, out in before), sys.stderr)


def register(app: typer.Typer) -> None:
    """Add `armcli expand` to the app."""
    app.command("expand")(expand_cmd)
