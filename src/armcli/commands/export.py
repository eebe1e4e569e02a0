"""`armcli export mjcf`: the robot as a MuJoCo model (plus scene.xml, meshes/)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.options import choice
from armcli.commands.robot_input import robot_options, write_notes
from armcli.defaults import MJCF_BASES
from armcli.io.outdir import check_output_file, existing
from armcli.io.terminal import say, say_line

if TYPE_CHECKING:
    from armcli.urdf.source import RobotInput

export_app = typer.Typer(
    help="Export the robot to other simulators' formats.", no_args_is_help=True
)


@export_app.command("mjcf")
@robot_options()
def mjcf_cmd(
    robot: RobotInput,
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
) -> None:
    """Write a MuJoCo MJCF model of ROBOT to OUT, with scene.xml (floor, light) beside it.

    Joints with spec gains get `position` actuators (kp = Kp, kv = Kd, force range =
    the effort limit); the report lists what MuJoCo cannot represent.
    """
    from armcli.compiler.expand import spec_label  # on use: `--help` stays light
    from armcli.export.mjcf_files import export_mjcf
    from armcli.export.mjcf_scene import SCENE

    before = existing(out, out.parent / SCENE)
    path = robot.file()
    check_output_file(out, "--out", [path], parents=True)  # before any work; never over it
    res = export_mjcf(
        path,
        out,
        base=base,
        whole_robot=whole_robot,
        trust_xacro=robot.trust,
        search=robot.packages,
        label=spec_label(path),
        inputs=robot.xacro,
    )
    write_notes(res.notes)
    exp = res.export
    say_line(f"{wrote_line(out, len(res.export.meshes), bool(before))} from {res.robot}")
    keyframes = ", ".join(exp.keyframes)
    say(f"{len(exp.joints)} joints, {len(exp.actuators)} actuators, keyframes: {keyframes}")
    say(res.report)
    say(res.verdict.text)


def wrote_line(out: Path, meshes: int, replaced: bool = False) -> str:
    """Which files the export wrote, by name: the model, its scene, and the mesh count.

    `replaced`: the model or the scene was there before (io.outdir.wrote's rule).
    """
    from armcli.export.mjcf_meshes import MESH_DIR
    from armcli.export.mjcf_scene import SCENE

    scene = out.parent / SCENE
    verb = "replaced" if replaced else "wrote"
    if not meshes:
        return f"{verb} {out} and {scene}"
    noun = "mesh" if meshes == 1 else "meshes"
    return f"{verb} {out}, {scene} and {meshes} {noun} in {out.parent / MESH_DIR}/"


def register(app: typer.Typer) -> None:
    """Add `armcli export ...` as a sub-app (one subcommand per format)."""
    app.add_typer(export_app, name="export")
