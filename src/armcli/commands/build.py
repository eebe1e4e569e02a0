"""`armcli build`: compile a spec into the xacro set and expanded URDFs."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.options import spec_argument
from armcli.io.oneline import one_line
from armcli.spec.discover import find_spec


@flag_errors({"out_dir": "--out"})  # the library names its parameter
def build_cmd(
    spec: Path | None = spec_argument(),
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

    spec = find_spec(spec)
    if check:
        check_fresh(spec, out)
        sys.stdout.write(one_line(f"{out}: up to date with {spec}") + "\n")
        return
    result = build(spec, out, force=force)
    sys.stdout.write(one_line(f"built {len(result.files)} files from {spec} into {out}/") + "\n")
    for f in result.files:
        sys.stdout.write(one_line(f"  {f}") + "\n")
    _report_check_errors(spec, result.files, result.spec)


def _report_check_errors(spec: Path, files: tuple[Path, ...], model: Any) -> None:
    """What `armcli check` will call an error in the built URDFs, said now (a warning each)."""
    from armcli.check.inputs import spec_document_errors

    urdfs = {p.name: p.read_bytes() for p in files if p.suffix == ".urdf"}
    for f in spec_document_errors(spec, urdfs, model):
        where = str(f.spec) if f.spec is not None else f.file
        sys.stderr.write(one_line(f"warning: {where}: {f.message} (check: {f.rule})") + "\n")


def register(app: typer.Typer) -> None:
    """Add the `build` command to the typer app."""
    app.command("build")(build_cmd)
