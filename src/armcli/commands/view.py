"""`armcli view`: a browser 3-D viewer with sliders, named poses and replay."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.help_text import ROBOT_HELP
from armcli.commands.options import spec_argument
from armcli.commands.xacro_inputs import (
    args_argument,
    env_option,
    package_dir_option,
    split_robot,
    write_notes,
    xacro_inputs,
)
from armcli.errors import InputError
from armcli.io.oneline import one_line
from armcli.spec.discover import find_spec
from armcli.xacro.trust import TRUST_XACRO_HELP, UNSANDBOXED_HELP, trust_mode


@flag_errors({"pose": "--pose", "q": "--q", "port": "--port", "replay": "--replay"})
def view_cmd(
    robot: Path | None = spec_argument(ROBOT_HELP),
    args: list[str] = args_argument(),
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
    package_dir: list[str] = package_dir_option(),
    env: list[str] = env_option(),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
    unsandboxed: bool = typer.Option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
) -> None:
    """Open a browser 3-D viewer with joint sliders, named poses and simulation replay."""
    from armcli.sim import rosbag  # on use: `--help` stays light
    from armcli.sim.states import load_replay
    from armcli.view.browser import Viewer
    from armcli.view.png import joint_limits, load_urdf
    from armcli.view.scene import load_robot, pose_q

    robot, tokens = split_robot(robot, args)
    inputs = xacro_inputs(tokens, env, package_dir)
    src = load_robot(
        find_spec(robot), trust_mode(trust_xacro, unsandboxed), inputs.packages, inputs
    )
    write_notes(src.notes)
    pose_q(src, pose, None)  # validate before starting the server
    if not 0 <= port <= 65535:
        raise InputError(f"{port} is not a port number", field="--port")
    run = None
    if replay is not None:
        names = list(joint_limits(load_urdf(src.xml, src.source, src.mesh_dir, src.search)))
        load = rosbag.load_replay if rosbag.is_mcap(replay) else load_replay
        run = load(replay, names)
    viewer = Viewer(
        src.xml,
        name=src.name,
        source=src.source,
        mesh_dir=src.mesh_dir,
        search=src.search,
        poses=src.poses,
        tool=src.tool,
        replay=run,
        host=host,
        port=port,
    )
    try:  # entered before the URL is printed, so an early Ctrl-C still stops cleanly
        if pose:
            viewer.apply_pose(pose)
        sys.stdout.write(
            one_line(f"armcli view: {src.name} at {viewer.url}  (Ctrl-C to stop)") + "\n"
        )
        sys.stdout.flush()
        viewer.serve_forever()
    except KeyboardInterrupt:
        sys.stdout.write("viewer stopped\n")
    finally:
        viewer.close()


def register(app: typer.Typer) -> None:
    """Add `armcli view` to the app."""
    app.command("view")(view_cmd)
