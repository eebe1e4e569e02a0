"""`armcli view`: a browser 3-D viewer with sliders, named poses and replay."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.options import spec_argument
from armcli.errors import InputError
from armcli.sim.states import load_replay
from armcli.spec.discover import find_spec
from armcli.urdf.meshes import MeshSearch, parse_package_dirs
from armcli.urdf.source import TRUST_XACRO_HELP, UNSANDBOXED_HELP, trust_mode
from armcli.view.browser import Viewer
from armcli.view.png import joint_limits, load_urdf
from armcli.view.scene import ROBOT_HELP, load_robot, pose_q


@flag_errors({"pose": "--pose", "q": "--q", "port": "--port", "replay": "--replay"})
def view_cmd(
    robot: Path | None = spec_argument(ROBOT_HELP),
    replay: Path = typer.Option(None, "--replay", help="A CSV written by `armcli simulate`."),
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
    package_dir: list[str] = typer.Option(
        [], "--package-dir", help="NAME=PATH for package://NAME/ mesh URIs (repeatable)."
    ),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
    unsandboxed: bool = typer.Option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
) -> None:
    """Open a browser 3-D viewer with joint sliders, named poses and simulation replay."""
    src = load_robot(
        find_spec(robot),
        trust_mode(trust_xacro, unsandboxed),
        MeshSearch(parse_package_dirs(package_dir)),
    )
    pose_q(src, pose, None)  # validate before starting the server
    if not 0 <= port <= 65535:
        raise InputError(f"{port} is not a port number", field="--port")
    run = None
    if replay is not None:
        names = list(joint_limits(load_urdf(src.xml, src.source, src.mesh_dir, src.search)))
        run = load_replay(replay, names)
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
        sys.stdout.write(f"armcli view: {src.name} at {viewer.url}  (Ctrl-C to stop)\n")
        sys.stdout.flush()
        viewer.serve_forever()
    except KeyboardInterrupt:
        sys.stdout.write("viewer stopped\n")
    finally:
        viewer.close()


def register(app: typer.Typer) -> None:
    """Add `armcli view` to the app."""
    app.command("view")(view_cmd)
