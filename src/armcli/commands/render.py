"""`armcli render`: draw the robot at a pose into a PNG, headless."""

from __future__ import annotations

import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.robot_input import robot_options, write_notes
from armcli.commands.values import REACH_POINT_HELP, Numbers, point, size
from armcli.io.outdir import existing, wrote
from armcli.io.terminal import say, say_line

if TYPE_CHECKING:
    from armcli.urdf.source import RobotInput

REACH_HELP = (
    "Also draw where the tool point can reach within the joint limits (sampled forward "
    "kinematics; joints off the arm stay at the pose) and print the envelope."
)


@flag_errors({"pose": "--pose", "q": "--q", "out": "--out", "reach": "--reach"})
@robot_options()
def render_cmd(
    robot: RobotInput,
    pose: str = typer.Option(None, "--pose", help="A named pose of the spec."),
    q: str = typer.Option(
        None,
        "--q",
        help="Joint values in rad (m if prismatic): '0.3,pi/4' in arm order, or 'joint=0.3,...'.",
    ),
    out: Path = typer.Option(
        Path("robot.png"),
        "-o",
        "--out",
        show_default=False,
        help="PNG to write (default: robot.png).",
    ),
    image_size: Numbers = typer.Option(
        "1200x600",
        "--size",
        parser=size,
        show_default=False,
        help="Image size WIDTHxHEIGHT in pixels (default: 1200x600).",
    ),
    reach: bool = typer.Option(False, "--reach", help=REACH_HELP),
    reach_point: list[Numbers] = typer.Option(
        [], "--reach-point", parser=point("--reach-point"), metavar="X,Y,Z", help=REACH_POINT_HELP
    ),
) -> None:
    """Draw the robot at a pose from two viewpoints into a PNG (headless, no GPU)."""
    from armcli.view.picture import render  # on use: `--help` stays light

    before = existing(out)
    pic = render(
        robot,
        out,
        pose=pose,
        q=q,
        size=(image_size[0], image_size[1]),
        reach=reach,
        targets=reach_point,
    )
    write_notes(pic.notes)
    for note in pic.snapped:
        say_line(f"note: {note}", sys.stderr)
    for warning in pic.warnings:  # drawn without them: a picture of the rest beats none
        say_line(f"warning: {warning}", sys.stderr)
    res = pic.result
    tip = (
        ""
        if res.tool_position is None
        else " tool at ({:.3f}, {:.3f}, {:.3f}) m".format(*res.tool_position)
    )
    say_line(
        f"{wrote(res.path, Path(res.path) in before)} ({res.width}x{res.height} px) at "
        f"{_drawn(pic.poses, pose, q)};{tip}"
    )
    for line in pic.lines:
        say(line)


def _drawn(poses: Mapping[str, Mapping[str, float]], pose: str | None, q: str | None) -> str:
    """Which configuration the picture shows, so a render without options is not a guess."""
    if pose is not None:
        return f"pose {pose!r}"
    if q is not None:
        return f"--q {q}"
    zero = [name for name, values in poses.items() if not any(values.values())]
    same = f", the pose {zero[0]!r}" if zero else ""
    others = f" (others: --pose {'|'.join(poses)})" if poses else ""
    return f"q = 0{same}, as no --pose or --q was given{others}"


def register(app: typer.Typer) -> None:
    """Add `armcli render` to the app."""
    app.command("render")(render_cmd)
