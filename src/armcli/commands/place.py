"""`armcli place`: where the base must stand for the tool to reach a point in the room."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.options import choice, option
from armcli.commands.robot_input import robot_options
from armcli.commands.values import Numbers, numbers
from armcli.errors import PlanningError
from armcli.io.terminal import say

if TYPE_CHECKING:
    from armcli.urdf.source import RobotInput

FORMATS = ("text", "json")
TARGET_HELP = "The point the tool must reach, x,y,z [m] in the scene's world frame."
START_HELP = "Where the base stands now, x,y,yaw [m, m, rad] (default: 0,0,0)."
SCENE_HELP = "Obstacles: YAML shaped like moveit_msgs/PlanningScene world.collision_objects."
TOLERANCE_HELP = "How near [m] the tool must come to the target (the region's bound)"
OUTPUT_HELP = "Write the Nav2 goal: geometry_msgs/PoseStamped YAML and its goal tolerances."
PLOT_HELP = "Draw the floor from above (objects, where the base may stand, the pose) as PNG."
FLAGS = {"target": "--target", "start": "--start", "tolerance": "--tolerance"}


@robot_options("spec")
def place_cmd(
    robot: RobotInput,
    target: Numbers = option(
        ...,
        "--target",
        parser=numbers("--target", 3, "x,y,z [m]"),
        metavar="X,Y,Z",
        help=TARGET_HELP,
    ),
    urdf: Path = option(None, "--urdf", help="Place this URDF or xacro file's robot instead."),
    scene: Path = option(None, "--scene", help=SCENE_HELP),
    start: Numbers = option(
        None,
        "--start",
        parser=numbers("--start", 3, "x,y,yaw [m, m, rad]"),
        metavar="X,Y,YAW",
        help=START_HELP,
    ),
    tolerance: float = option(0.01, "--tolerance", help=TOLERANCE_HELP),
    output: Path = option(None, "--output", "-o", help=OUTPUT_HELP),
    plot: Path = option(None, "--plot", help=PLOT_HELP),
    fmt: str = choice("text", FORMATS, "--format", help="Output format (default: text)."),
) -> None:
    """Find where the base must stand for the tool to reach a point: least driving first."""
    from armcli.io.outdir import check_output_file, check_png_file
    from armcli.plan.mobile.placing import failed_document, place_robot

    if output is not None:
        check_output_file(output, "--output")
    if plot is not None:
        check_png_file(plot, "--plot")
    robot_file = robot.read(urdf)
    try:
        with flag_errors(FLAGS):
            placed = place_robot(robot_file, target, scene=scene, start=start or (0.0, 0.0, 0.0),
                                 tolerance=tolerance, search=robot.packages)  # fmt: skip
    except PlanningError as exc:
        if fmt == "json":
            _json(failed_document(exc.reason))
            raise typer.Exit(1) from None
        raise
    files = placed.files(output, plot)
    if files:
        from armcli.io.together import write_files_together

        write_files_together(files)
    if fmt == "json":
        _json(placed.document())
        return
    say("\n".join([*placed.lines(), *(f"wrote {p}" for p in files)]))


def _json(doc: dict[str, Any]) -> None:
    from armcli.io.jsondoc import dumps

    sys.stdout.write(dumps(doc))


def register(app: typer.Typer) -> None:
    """Add the `place` command to the typer app."""
    app.command("place")(place_cmd)
