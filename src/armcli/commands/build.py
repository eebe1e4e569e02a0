"""`armcli build`: compile a spec into the xacro set and expanded URDFs."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.robot_input import robot_options
from armcli.io.terminal import say_line

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec
    from armcli.urdf.source import RobotInput


@flag_errors({"out_dir": "--out"})  # the library names its parameter
@robot_options("spec", xacro=False, packages=False)
def build_cmd(
    robot: RobotInput,
    out: Path = typer.Option(
        Path("urdf"), "-o", "--out", show_default=False, help="Output directory (default: urdf)."
    ),
    check: bool = typer.Option(
        False, "--check", help="Do not write; exit 1 listing files that differ from a fresh build."
    ),
    force: bool = typer.Option(
        False, "--force", help="Write into an existing non-empty directory armcli did not create."
    ),
) -> None:
    """Compile SPEC into the course's xacro set and the expanded URDFs."""
    from armcli.compiler.expand import build, check_fresh  # on use: `--help` stays light

    spec = robot.file()
    if check:
        check_fresh(spec, out)
        say_line(f"{out}: up to date with {spec}")
        return
    result = build(spec, out, force=force)
    say_line(f"built {len(result.files)} files from {spec} into {out}/")
    for f in result.files:
        say_line(f"  {f}")
    _report_check_errors(spec, result.spec)


def _report_check_errors(spec: Path, doc: RobotSpec) -> None:
    """What `armcli check` will call an error in the built URDFs, said now (a warning each).

    The URDFs `check SPEC` reads (meshes resolved from the spec), not the written ones:
    those name their meshes relative to the output directory.
    """
    from armcli.check.inputs import spec_document_errors
    from armcli.urdf.source import spec_urdfs

    for f in spec_document_errors(spec, spec_urdfs(doc), doc):
        where = str(f.spec) if f.spec is not None else f.file
        say_line(f"warning: {where}: {f.message} (check: {f.rule})", sys.stderr)


def register(app: typer.Typer) -> None:
    """Add the `build` command to the typer app."""
    app.command("build")(build_cmd)
