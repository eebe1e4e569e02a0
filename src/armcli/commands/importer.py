"""`armcli import`: start a spec from the URDF or xacro you have."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.options import option
from armcli.commands.robot_input import robot_options, write_notes
from armcli.defaults import SPEC_FILE
from armcli.io.oneline import one_line
from armcli.io.terminal import say

if TYPE_CHECKING:  # the importer is imported when the command runs: `--help` stays light
    from armcli.importer.run import ImportResult
    from armcli.urdf.source import RobotInput


def report(result: ImportResult, source: Path, out: Path) -> str:
    """What the import did, in a few lines: counts, what was kept verbatim, the round trip."""
    spec = result.spec
    links, joints = spec.all_links(), spec.all_joints()
    derived = sum(1 for lk in links.values() if (s := lk.inertial_source()) is not None and s.shape)
    lines = [
        f"imported {source} into {out}: robot {spec.name!r}, {len(links)} links "
        f"({derived} inertials derived from shapes), {len(joints)} joints"
        + (f", arm from {spec.arm_root()!r} on a mobile base" if spec.mounted_base() else ""),
    ]
    if result.passthrough:
        lines.append(f"kept verbatim ({len(result.passthrough)}, spec field `passthrough`):")
        lines += [f"  {p}" for p in result.passthrough]
    lines += [f"note: {n}" for n in result.notes]
    if result.differences:
        lines.append(
            f"round trip: `armcli build` gives a URDF that differs in {len(result.differences)} "
            "place(s):"
        )
        lines += [f"  {d}" for d in result.differences]
    else:
        lines.append("round trip: `armcli build` gives back the same URDF (checked)")
    # every line through the one escaper: passthrough text and differences come from the file
    return "".join(f"{one_line(line)}\n" for line in lines)


@flag_errors({"out": "--out", "arm_root": "--arm-root", "force": "--force"})
@robot_options("file", help="URDF or xacro file to import.")
def import_cmd(
    robot: RobotInput,
    out: Path = option(SPEC_FILE, "-o", "--out", help="Spec file to write"),
    arm_root: str | None = option(
        None, "--arm-root", help="Link where the arm starts (default: found from the joints)."
    ),
    force: bool = typer.Option(False, "--force", help="Replace an existing spec file."),
    strict: bool = typer.Option(
        False, "--strict", help="Exit 1 when the round trip is not exact (the spec is written)."
    ),
) -> None:
    """Import a URDF or xacro file into a spec that builds the same URDF back."""
    from armcli.importer.file import import_file
    from armcli.tune.spec_start import spec_start_gains

    file = robot.file()
    result, notes = import_file(
        file,
        out,
        inputs=robot.xacro,
        trust_xacro=robot.trust,
        arm_root=arm_root,
        force=force,
        gains=spec_start_gains,
    )
    write_notes(notes)
    say(report(result, file, out))
    if strict and result.differences:
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    """Add `import` to the app."""
    app.command("import")(import_cmd)
