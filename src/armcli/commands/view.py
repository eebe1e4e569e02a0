"""`armcli view`: a browser 3-D viewer with sliders, named poses, replay and a planning panel."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.robot_input import robot_options, write_notes
from armcli.commands.values import Names, names
from armcli.io.oneline import one_line

if TYPE_CHECKING:
    from armcli.urdf.source import RobotInput

SCENE_HELP = "Obstacles for the planning panel: YAML like moveit_msgs/PlanningScene."
SRDF_HELP = "SRDF of a URDF: its named poses (group_state) and disabled collision pairs."
JOINTS_HELP = "Joints the planning panel plans, comma-separated (default: the arm's)."
GROUP_HELP = "The planning panel plans this planning group of --srdf (MoveIt's), e.g. arm."
SAVE_HELP = "Directory the planning panel's Save writes into (default: the current one)."


@flag_errors(
    {
        "pose": "--pose",
        "q": "--q",
        "port": "--port",
        "replay": "--replay",
        "joints": "--joints",
        "group": "--group",
        "srdf": "--srdf",
        "save_dir": "--save-dir",
    }
)
@robot_options()
def view_cmd(
    robot: RobotInput,
    replay: Path = typer.Option(
        None, "--replay", help="A run written by `armcli simulate -o` (.csv or .mcap)."
    ),
    pose: str = typer.Option(None, "--pose", help="Start at this named pose."),
    host: str = typer.Option(
        "127.0.0.1", "--host", show_default=False, help="Address to listen on (default: 127.0.0.1)."
    ),
    port: int = typer.Option(
        8080,
        "--port",
        show_default=False,
        help="Port to listen on (default: 8080; 0: any free port).",
    ),
    scene: Path = typer.Option(None, "--scene", help=SCENE_HELP),
    srdf: Path = typer.Option(None, "--srdf", help=SRDF_HELP),
    joints: Names = typer.Option(
        None, "--joints", parser=names, metavar="JOINT,...", help=JOINTS_HELP
    ),
    group: str = typer.Option(None, "--group", help=GROUP_HELP),
    save_dir: Path = typer.Option(Path("."), "--save-dir", show_default=False, help=SAVE_HELP),
) -> None:
    """Open a browser 3-D viewer: joint sliders, named poses, replay, motion planning."""
    from armcli.view.launch import ViewRequest, open_viewer  # on use: `--help` stays light

    chosen = tuple(joints) if joints else None
    request = ViewRequest(replay, pose, host, port, scene, srdf, chosen, group, save_dir)
    app = open_viewer(robot, request, write_notes)
    try:  # entered before the URL is printed, so an early Ctrl-C still stops cleanly
        line = f"armcli view: {app.name} at {app.viewer.url}  (Ctrl-C to stop)"
        sys.stdout.write(one_line(line) + "\n")  # whole, never fitted: the URL carries a token
        sys.stdout.flush()
        app.serve()
    except KeyboardInterrupt:
        sys.stdout.write("viewer stopped\n")
    finally:
        app.close()


def register(app: typer.Typer) -> None:
    """Add `armcli view` to the app."""
    app.command("view")(view_cmd)
