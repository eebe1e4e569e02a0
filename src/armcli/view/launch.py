"""The viewer `armcli view` serves: the robot, a replay, and the panels its inputs allow.

Why a module: the command is options -> `open_viewer` -> print the URL and serve. What
panels a robot gets (planning when it can be planned for, the mobile base's when it has a
diff drive) and what is refused before the server starts are the library's decisions.
Notes are handed to `say` as they arise, so a refusal after a note still shows the note.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from armcli.errors import ArmcliError, InputError

if TYPE_CHECKING:
    from armcli.urdf.source import RobotInput
    from armcli.view.baseplan import BaseSession
    from armcli.view.browser import Viewer
    from armcli.view.planning import PlanningSession
    from armcli.view.scene import RobotSource

Say = Callable[[Iterable[str]], None]


@dataclass(frozen=True)
class ViewRequest:
    """What the user asked the viewer for (field names are the command's options)."""

    replay: Path | None = None
    pose: str | None = None
    host: str = "127.0.0.1"
    port: int = 8080
    scene: Path | None = None
    srdf: Path | None = None
    joints: tuple[str, ...] | None = None
    group: str | None = None
    save_dir: Path = Path(".")


@dataclass
class ViewerApp:
    """A viewer ready to serve, with the panels attached; `close()` stops them all."""

    name: str
    viewer: Viewer
    panels: list[Any]

    def serve(self) -> None:
        """Serve until interrupted."""
        self.viewer.serve_forever()

    def close(self) -> None:
        """Stop the panels, then the viewer."""
        for panel in self.panels:
            panel.close()
        self.viewer.close()


def open_viewer(robot: RobotInput, req: ViewRequest, say: Say) -> ViewerApp:
    """The viewer for `robot`, refused (InputError naming the field) before any server starts."""
    from armcli.view.scene import load_robot, pose_q

    src = load_robot(robot)
    say(src.notes)
    pose_q(src, req.pose, None)  # validate before starting the server
    if not 0 <= req.port <= 65535:
        raise InputError(f"{req.port} is not a port number", field="port")
    session = _session(src, req, say)  # before serving
    base = _base_session(src, req.scene, say) if session is not None else None
    viewer = _viewer(src, req, mobile=base is not None)
    say(viewer.sensor_notes)
    app = ViewerApp(src.name, viewer, [])
    try:
        _attach(app, src, session, base)
        if req.pose:
            viewer.apply_pose(req.pose)
    except BaseException:
        app.close()
        raise
    return app


def _viewer(src: RobotSource, req: ViewRequest, mobile: bool) -> Viewer:
    """The browser viewer, with the replay and its sensors when one is given."""
    from armcli.view.browser import Viewer

    run, sensors = _replay(src, req.replay) if req.replay is not None else (None, None)
    kind = Viewer
    if mobile:
        from armcli.view.basepanel import MobileViewer

        kind = MobileViewer
    return kind(
        src.xml,
        name=src.name,
        source=src.source,
        mesh_dir=src.mesh_dir,
        search=src.search,
        poses=src.poses,
        tool=src.tool,
        replay=run,
        sensors=sensors,
        host=req.host,
        port=req.port,
    )


def _replay(src: RobotSource, replay: Path) -> tuple[Any, Any]:
    """A run written by `simulate -o` (.csv or .mcap) and, in an MCAP, its sensor readings."""
    from armcli.sim import rosbag
    from armcli.sim.states import load_replay
    from armcli.view.png import joint_limits, load_urdf

    names = list(joint_limits(load_urdf(src.xml, src.source, src.mesh_dir, src.search)))
    if not rosbag.is_mcap(replay):
        return load_replay(replay, names), None
    from armcli.sim.sensors.replay import load_sensor_replay

    return rosbag.load_replay(replay, names), load_sensor_replay(replay)


def _attach(
    app: ViewerApp, src: RobotSource, session: PlanningSession | None, base: BaseSession | None
) -> None:
    """The planning panel and the mobile base's panel, on the viewer."""
    where = (src.source, src.mesh_dir, src.search)
    if session is not None:
        from armcli.view.panel import PlanningPanel

        source, mesh_dir, search = where
        panel = PlanningPanel(
            app.viewer, session, src.xml, source=source, mesh_dir=mesh_dir, search=search
        )
        app.panels.append(panel)
    if base is not None:
        from armcli.view.basepanel import BasePanel, MobileViewer

        assert isinstance(app.viewer, MobileViewer)
        source, mesh_dir, search = where
        app.panels.append(
            BasePanel(app.viewer, base, src.xml, source=source, mesh_dir=mesh_dir, search=search)
        )


def _session(src: RobotSource, req: ViewRequest, say: Say) -> PlanningSession | None:
    """The planning panel's session; a robot that cannot be planned for gets none (a note)."""
    from armcli.view.planning import load_session

    if not req.save_dir.is_dir():
        raise InputError(f"{req.save_dir} is not a directory", field="save_dir")
    assert src.file is not None
    joints = list(req.joints) if req.joints else None
    try:
        return load_session(
            src.file,
            srdf=req.srdf,
            scene=req.scene,
            joints=joints,
            group=req.group,
            search=src.search,
            save_dir=req.save_dir,
        )
    except InputError as exc:
        if any(given is not None for given in (req.scene, req.srdf, joints, req.group)):
            raise  # asked for planning: refuse
        say([f"note: no planning panel: {exc}"])
        return None


def _base_session(src: RobotSource, scene: Path | None, say: Say) -> BaseSession | None:
    """The mobile base's session when the robot has a diff drive (else none, a note)."""
    from armcli.view.baseplan import load_base_session

    assert src.file is not None
    try:
        return load_base_session(src.file, scene, src.search)
    except ArmcliError as exc:
        say([f"note: no mobile base panel: {exc}"])
        return None
