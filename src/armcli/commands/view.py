"""`armcli view`: a browser 3-D viewer with sliders, named poses, replay and a planning panel."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.robot_input import robot_options, write_notes
from armcli.commands.values import Names, names
from armcli.errors import ArmcliError, InputError
from armcli.io.oneline import one_line
from armcli.io.terminal import say_line

if TYPE_CHECKING:
    from armcli.urdf.source import RobotInput
    from armcli.view.baseplan import BaseSession
    from armcli.view.planning import PlanningSession
    from armcli.view.scene import RobotSource

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
    from armcli.sim import rosbag  # on use: `--help` stays light
    from armcli.sim.states import load_replay
    from armcli.view.browser import Viewer
    from armcli.view.panel import PlanningPanel
    from armcli.view.png import joint_limits, load_urdf
    from armcli.view.scene import load_robot, pose_q

    src = load_robot(robot)
    write_notes(src.notes)
    pose_q(src, pose, None)  # validate before starting the server
    if not 0 <= port <= 65535:
        raise InputError(f"{port} is not a port number", field="--port")
    run, sensors = None, None
    if replay is not None:
        names = list(joint_limits(load_urdf(src.xml, src.source, src.mesh_dir, src.search)))
        load = rosbag.load_replay if rosbag.is_mcap(replay) else load_replay
        run = load(replay, names)
        if rosbag.is_mcap(replay):
            from armcli.sim.sensors.replay import load_sensor_replay

            sensors = load_sensor_replay(replay)
    chosen = list(joints) if joints else None
    session = _session(src, (scene, srdf, chosen, group), save_dir, robot)  # before serving
    base = _base_session(src, scene) if session is not None else None
    kind = Viewer
    if base is not None:
        from armcli.view.basepanel import MobileViewer

        kind = MobileViewer
    viewer = kind(
        src.xml,
        name=src.name,
        source=src.source,
        mesh_dir=src.mesh_dir,
        search=src.search,
        poses=src.poses,
        tool=src.tool,
        replay=run,
        sensors=sensors,
        host=host,
        port=port,
    )
    write_notes(viewer.sensor_notes)
    panel = base_panel = None
    try:  # entered before the URL is printed, so an early Ctrl-C still stops cleanly
        if session is not None:
            panel = PlanningPanel(
                viewer,
                session,
                src.xml,
                source=src.source,
                mesh_dir=src.mesh_dir,
                search=src.search,
            )
        if base is not None:
            from armcli.view.basepanel import BasePanel, MobileViewer

            assert isinstance(viewer, MobileViewer)
            base_panel = BasePanel(
                viewer, base, src.xml, source=src.source, mesh_dir=src.mesh_dir, search=src.search
            )
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
        if panel is not None:
            panel.close()
        if base_panel is not None:
            base_panel.close()
        viewer.close()


def _session(
    src: RobotSource,
    planning: tuple[Path | None, Path | None, list[str] | None, str | None],
    save_dir: Path,
    robot: RobotInput,
) -> PlanningSession | None:
    """The planning panel's session; a robot that cannot be planned for gets none (a note)."""
    from armcli.view.planning import load_session

    scene, srdf, joints, group = planning
    if not save_dir.is_dir():
        raise InputError(f"{save_dir} is not a directory", field="--save-dir")
    assert src.file is not None
    try:
        session = load_session(
            src.file,
            srdf=srdf,
            scene=scene,
            joints=joints,
            group=group,
            search=src.search,
            save_dir=save_dir,
        )
    except InputError as exc:
        if any(given is not None for given in planning):  # asked for planning: refuse
            raise
        say_line(f"note: no planning panel: {exc}", sys.stderr)
        return None
    return session


def _base_session(src: RobotSource, scene: Path | None) -> BaseSession | None:
    """The mobile base's session when the robot has a diff drive (else none, a note)."""
    from armcli.view.baseplan import load_base_session

    assert src.file is not None
    try:
        return load_base_session(src.file, scene, src.search)
    except ArmcliError as exc:
        sys.stderr.write(f"note: no mobile base panel: {exc}\n")
        return None


def register(app: typer.Typer) -> None:
    """Add `armcli view` to the app."""
    app.command("view")(view_cmd)
