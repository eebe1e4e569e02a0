"""`armcli init`: start a project outside the repository from a shipped example."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click
import typer

from armcli.commands.flags import flag_errors
from armcli.commands.importer import report
from armcli.commands.robot_input import write_notes
from armcli.defaults import SPEC_FILE, TRAJECTORY_DIR
from armcli.io.oneline import one_line
from armcli.io.terminal import say
from armcli.spec.scaffold import DEFAULT_TEMPLATE, TEMPLATES, init_project


@flag_errors({"template": "--template"})
def init_cmd(
    directory: Path = typer.Argument(
        Path("."), show_default=False, help="Where to write (created if missing; default: here)."
    ),
    template: str = typer.Option(
        DEFAULT_TEMPLATE,
        "--template",
        click_type=click.Choice(tuple(TEMPLATES)),
        show_default=False,
        help="course (default: a 2-axis arm on a mobile base), rover (the course robot with "
        "lidar, depth camera, IMU and a world) or tabletop (a 3-axis arm).",
    ),
    source: Path | None = typer.Option(
        None,
        "--from",
        help="Start from this URDF or xacro file instead (as `armcli import`).",
    ),
) -> None:
    """Write an example spec (armcli.yaml), its trajectories and a README; never overwrites."""
    if source is not None:
        from armcli.importer.file import import_file  # on use: `--help` stays light
        from armcli.tune.spec_start import spec_start_gains

        directory.mkdir(parents=True, exist_ok=True)
        out = directory / SPEC_FILE
        result, notes = import_file(source, out, gains=spec_start_gains)
        write_notes(notes)
        say(report(result, source, out))
        return
    written = init_project(directory, template)
    where = "." if directory == Path(".") else str(directory)
    sys.stdout.write(one_line(f"wrote {len(written)} files into {where}{os.sep}") + "\n")
    for path in written:
        sys.stdout.write(one_line(f"  {path}") + "\n")
    pick = (TRAJECTORY_DIR / "pick.yaml").as_posix()
    steps = [] if where == "." else [f"cd {where}"]
    steps += ["armcli build", "armcli check", f"armcli simulate --trajectory {pick}"]
    say(f"next (commands read ./{SPEC_FILE} when no spec is given):")
    for step in steps:  # one command a line: whole, to copy, at any width
        sys.stdout.write(one_line(f"  {step}") + "\n")


def register(app: typer.Typer) -> None:
    """Add `init` to the app."""
    app.command("init")(init_cmd)
