"""`armcli import`: start a spec from the URDF or xacro you have."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.options import option
from armcli.commands.xacro_inputs import (
    env_option,
    package_dir_option,
    write_notes,
    xacro_inputs,
)
from armcli.defaults import SPEC_FILE
from armcli.errors import InputError
from armcli.io.oneline import one_line
from armcli.io.terminal import say
from armcli.xacro.trust import TRUST_XACRO_HELP, UNSANDBOXED_HELP, trust_mode

if TYPE_CHECKING:  # the importer is imported when the command runs: `--help` stays light
    from armcli.importer.run import ImportResult


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
def import_cmd(
    file: Path = typer.Argument(..., help="URDF or xacro file to import."),
    args: list[str] = typer.Argument(
        None, help="xacro arguments NAME:=VALUE (safe mode or --trust-xacro)."
    ),
    out: Path = option(SPEC_FILE, "-o", "--out", help="Spec file to write"),
    arm_root: str | None = option(
        None, "--arm-root", help="Link where the arm starts (default: found from the joints)."
    ),
    force: bool = typer.Option(False, "--force", help="Replace an existing spec file."),
    strict: bool = typer.Option(
        False, "--strict", help="Exit 1 when the round trip is not exact (the spec is written)."
    ),
    package_dir: list[str] = package_dir_option(),
    env: list[str] = env_option(),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
    unsandboxed: bool = typer.Option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
) -> None:
    """Import a URDF or xacro file into a spec that builds the same URDF back."""
    from armcli.importer.file import import_file
    from armcli.tune.spec_start import spec_start_gains

    stray = [a for a in args or [] if ":=" not in a]
    if stray:
        raise InputError(f"unexpected argument {stray[0]!r}: expected NAME:=VALUE", field="ARGS")
    result, notes = import_file(
        file,
        out,
        inputs=xacro_inputs(args or [], env, package_dir),
        trust_xacro=trust_mode(trust_xacro, unsandboxed),
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
