"""`armcli export mjcf`: the robot as a MuJoCo model (plus scene.xml, meshes/)."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from armcli.commands.options import choice
from armcli.commands.xacro_inputs import (
    args_argument,
    env_option,
    package_dir_option,
    split_robot,
    write_notes,
    xacro_inputs,
)
from armcli.defaults import MJCF_BASES
from armcli.io.outdir import check_output_file
from armcli.spec.discover import find_spec
from armcli.xacro.trust import TRUST_XACRO_HELP, UNSANDBOXED_HELP, trust_mode

export_app = typer.Typer(
    help="Export the robot to other simulators' formats.", no_args_is_help=True
)


@export_app.command("mjcf")
def mjcf_cmd(
    robot: Path | None = typer.Argument(
        None,
        show_default=False,
        help="Robot spec YAML, URDF or xacro file (default: ./armcli.yaml, else the spec in "
        "specs/).",
    ),
    args: list[str] = args_argument(),
    out: Path = typer.Option(
        Path("robot.xml"),
        "-o",
        "--out",
        show_default=False,
        help="MJCF model file (default: robot.xml).",
    ),
    base: str = choice(
        "fixed",
        MJCF_BASES,
        "--base",
        help="fixed (default): the root link is welded to the world; free: on a free joint.",
    ),
    whole_robot: bool = typer.Option(
        False, "--whole-robot", help="For a spec: the whole robot instead of the arm alone."
    ),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
    unsandboxed: bool = typer.Option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
    package_dir: list[str] = package_dir_option(),
    env: list[str] = env_option(),
) -> None:
    """Write a MuJoCo MJCF model of ROBOT to OUT, with scene.xml (floor, light) beside it.

    Joints with spec gains get `position` actuators (kp = Kp, kv = Kd, force range =
    the effort limit); the report lists what MuJoCo cannot represent.
    """
    from armcli.compiler.expand import spec_label  # on use: `--help` stays light
    from armcli.export.mjcf_files import export_mjcf

    check_output_file(out, "--out", parents=True)  # before any work: nothing else is written
    robot, tokens = split_robot(robot, args)
    inputs = xacro_inputs(tokens, env, package_dir)
    robot = find_spec(robot)
    res = export_mjcf(
        robot,
        out,
        base=base,
        whole_robot=whole_robot,
        trust_xacro=trust_mode(trust_xacro, unsandboxed),
        search=inputs.packages,
        label=spec_label(robot),
        inputs=inputs,
    )
    write_notes(res.notes)
    exp = res.export
    w = sys.stdout.write
    w(f"{wrote_line(out, len(res.export.meshes))} from {res.robot}\n")
    w(
        f"{len(exp.joints)} joints, {len(exp.actuators)} actuators, "
        f"keyframes: {', '.join(exp.keyframes)}\n"
    )
    w(res.report)
    w(f"{res.verdict.text}\n")


def wrote_line(out: Path, meshes: int) -> str:
    """Which files the export wrote, by name: the model, its scene, and the mesh count."""
    from armcli.export.mjcf_meshes import MESH_DIR
    from armcli.export.mjcf_scene import SCENE

    scene = out.parent / SCENE
    if not meshes:
        return f"wrote {out} and {scene}"
    noun = "mesh" if meshes == 1 else "meshes"
    return f"wrote {out}, {scene} and {meshes} {noun} in {out.parent / MESH_DIR}/"


def register(app: typer.Typer) -> None:
    """Add `armcli export ...` as a sub-app (one subcommand per format)."""
    app.add_typer(export_app, name="export")
