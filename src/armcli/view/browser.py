"""A browser 3-D viewer of a URDF: joint sliders, named poses, frames, and replay of a run.

This stands in for RViz + joint_state_publisher_gui for users without ROS. viser
serves a web page (WebGL) and draws the URDF through yourdfpy; both are
imported lazily. The `Viewer` class is the Python API the CLI and the tests
drive; it binds 127.0.0.1 by default and refuses a taken port instead of
silently moving to the next one (viser's own behaviour).
"""

from __future__ import annotations

import contextlib
import io
import math
import socket
import threading
import time
from collections.abc import Collection, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from armcli.errors import InputError
from armcli.io.names import did_you_mean
from armcli.robot.frames import matrix_quaternion
from armcli.robot.tool import ToolPoint
from armcli.sim.sensors.replay import SensorReplay
from armcli.sim.states import Replay
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.read import parse_root
from armcli.urdf.tree import parse_tree
from armcli.view.origin import TOKEN_PARAM, checked_requests, new_token
from armcli.view.png import (
    full_configuration,
    joint_limits,
    load_urdf,
    neutral,
    tool_position,
)
from armcli.view.sensors import SensorLayer

GHOST_RGBA = (0.35, 0.65, 1.0, 0.35)  # translucent blue for the reference pose
FRAME_RATE = 30.0  # [Hz] replay updates sent to the browser
SLIDER_STEP = 1e-3  # [rad] or [m]
FRAME_AXES = 0.12  # [m] length of link-frame axes


def check_port_free(host: str, port: int) -> None:
    """Raise InputError if (host, port) cannot be bound, as the server would need it."""
    if port == 0:
        return
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as asyncio's server does
        try:
            s.bind((host, port))
        except OSError as exc:
            raise InputError(
                f"cannot listen on {host}:{port}: {exc.strerror}; "
                "choose another `port` (0: any free port)",
                field="port",
            ) from None


def moving_parts(urdf_xml: str, joints: Collection[str], source: str = "<urdf>") -> str:
    """The URDF with visuals kept only on links that `joints` move (for the reference ghost).

    A whole-robot ghost would tint the base, which never differs from the reference.
    """
    from lxml import etree

    tree = parse_tree(urdf_xml, source)
    moving: set[str] = set()
    for _, j in tree.walk():  # parents come before children
        if j.name in joints or j.parent in moving:
            moving.add(str(j.child))
    root = parse_root(urdf_xml.encode("utf-8"), source)
    for link in root.findall("link"):
        if link.get("name") not in moving:
            for visual in link.findall("visual"):
                link.remove(visual)
    return etree.tostring(root, encoding="unicode")


class Viewer:
    """A running viser server showing one robot; thread-safe setters for the tests and the GUI."""

    MOBILE = False  # the robot hangs from a frame that moves (view.basepanel.MobileViewer)

    def __init__(
        self,
        urdf_xml: str,
        *,
        name: str = "robot",
        source: str = "<urdf>",
        mesh_dir: str | Path | None = None,
        search: MeshSearch | None = None,
        poses: Mapping[str, Mapping[str, float]] | None = None,
        tool: ToolPoint | None = None,
        replay: Replay | None = None,
        sensors: SensorReplay | None = None,
        host: str = "127.0.0.1",
        port: int = 8080,
    ) -> None:
        import viser
        from viser.extras import ViserUrdf

        self._source, self._tool, self._replay = source, tool, replay
        self._poses = {k: dict(v) for k, v in (poses or {}).items()}
        self._urdf = load_urdf(urdf_xml, source, mesh_dir, search)
        self._limits = joint_limits(self._urdf)
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._playing = False
        check_port_free(host, port)
        self.token = new_token()  # every request must carry it (view.origin)
        # viser prints a banner (the CLI prints its own); Host, Origin, token checked
        with contextlib.redirect_stdout(io.StringIO()), checked_requests(host, self.token):
            self.server = viser.ViserServer(
                host=host, port=port, label=f"armcli: {name}", verbose=False
            )
        if port and self.server.get_port() != port:  # lost a race for the port
            self._stop_server()
            check_port_free(host, port)
        self.host, self.port = host, int(self.server.get_port())
        self._player: threading.Thread | None = None
        try:
            # a drive's replay moves the whole robot: its URDF hangs from a frame placed at
            # the base's pose in the world (states' base.*, MCAP's world -> odom -> base)
            moving = self.MOBILE or (replay is not None and replay.base is not None)
            self._base = self.server.scene.add_frame("/base", show_axes=False) if moving else None
            # everything drawn in the robot's root frame hangs from it too: the frames, the
            # tool dot, the planning panel's goal ghost, handle and trail (view.panel)
            self.root = root = "/base" if moving else ""
            self._robot = ViserUrdf(self.server, self._urdf, root_node_name=f"{root}/robot")
            self._ghost = None
            if replay is not None and replay.reference:
                ghost_xml = moving_parts(urdf_xml, replay.reference, source)
                self._ghost = ViserUrdf(
                    self.server,
                    load_urdf(ghost_xml, source, mesh_dir, search),
                    root_node_name=f"{root}/ghost",
                    mesh_color_override=GHOST_RGBA,
                )
            self._build_scene()  # then the sensors: a world's camera replaces the robot's
            self._sensors = (
                SensorLayer(self.server, self._urdf, sensors, f"{root}/robot")
                if (sensors is not None and replay is not None)
                else None
            )
            self._build_gui(name)
            self._apply()
        except BaseException:
            self._stop.set()
            self._stop_server()
            raise
        if replay is not None:
            self._player = threading.Thread(target=self._play_loop, daemon=True)
            self._player.start()

    # -- public API ------------------------------------------------------------------
    @property
    def url(self) -> str:
        """Address of the viewer page, with the run's token (the page sets it as a cookie)."""
        return f"http://{self.host}:{self.port}/?{TOKEN_PARAM}={self.token}"

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The movable joints the sliders control, in yourdfpy's order."""
        return tuple(self._limits)

    def configuration(self) -> dict[str, float]:
        """Current joint values [rad or m] in yourdfpy's movable-joint order."""
        with self._lock:
            return {n: float(s.value) for n, s in self._sliders.items()}

    def set_configuration(self, q: Mapping[str, float]) -> None:
        """Move the named joints (others keep theirs); unknown or out of limits: InputError."""
        full_configuration(self._urdf, q, field="q")
        with self._lock:
            self._batch = True
            try:
                for name, value in q.items():
                    self._sliders[name].value = float(value)
            finally:
                self._batch = False
            self._apply()

    def apply_pose(self, name: str) -> None:
        """Move to a named pose of the spec (joints it does not name go to `neutral`)."""
        if name not in self._poses:
            known = ", ".join(self._poses) or "(none)"
            raise InputError(
                f"unknown pose {name!r}; {did_you_mean(name, self._poses)}known: {known}",
                field="pose",
            )
        pose = self._poses[name]
        self.set_configuration({j: pose.get(j, neutral(lim)) for j, lim in self._limits.items()})

    def tool_position(self) -> np.ndarray | None:
        """The end-effector point in the root-link frame [m], or None without a tool."""
        with self._lock:
            return tool_position(self._urdf, self._tool)

    def show_frames(self, visible: bool) -> None:
        """Show or hide the link frames, through the GUI checkbox so the page stays in sync."""
        self._frames_box.value = bool(visible)

    @property
    def sensor_notes(self) -> tuple[str, ...]:
        """What the replay's sensors could not draw."""
        return self._sensors.notes if self._sensors is not None else ()

    def seek(self, t: float) -> None:
        """Show the replay at time t [s] from the start of the record."""
        if self._replay is None:
            raise InputError("no replay loaded", field="replay")
        self._time_slider.value = float(np.clip(t, 0.0, self._replay.duration))

    def play(self, playing: bool = True) -> None:
        """Start or pause the replay; without a replay it stays paused."""
        self._playing = bool(playing) and self._replay is not None

    @property
    def playing(self) -> bool:
        """Whether the replay is running."""
        return self._playing

    def ghost_visible(self) -> bool:
        """Whether the reference ghost is drawn (only with a replay that has references)."""
        return self._ghost is not None and self._ghost.show_visual

    def serve_forever(self) -> None:
        """Block until Ctrl-C (KeyboardInterrupt propagates after shutting down)."""
        try:
            while not self._stop.wait(0.25):
                pass
        finally:
            self.close()

    def close(self) -> None:
        """Stop the replay thread and the server; safe to call twice."""
        if self._stop.is_set():
            return
        self._stop.set()
        if self._player is not None:
            self._player.join(timeout=2.0)
        self._stop_server()

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- internals -----------------------------------------------------------------
    def _stop_server(self) -> None:
        with contextlib.redirect_stdout(io.StringIO()):  # viser prints "Server stopped"
            self.server.stop()

    def _build_scene(self) -> None:
        scene = self.server.scene
        scene.set_up_direction("+z")
        scene.add_grid("/grid", width=2.0, height=2.0, cell_size=0.1, section_size=0.5)
        lo, hi = np.asarray(self._urdf.scene.bounds)
        centre, size = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
        self.server.initial_camera.look_at = tuple(centre)
        self.server.initial_camera.position = tuple(centre + size * np.array([0.55, -0.75, 0.45]))
        self._frames = {
            link: scene.add_frame(
                f"{self.root}/frames/{link}",
                axes_length=FRAME_AXES,
                axes_radius=0.003,
                visible=False,
            )
            for link in self._urdf.link_map
        }
        self._tool_marker = None
        if self._tool is not None:
            self._tool_marker = scene.add_icosphere(
                f"{self.root}/tool", radius=0.012, color=(20, 20, 20)
            )

    def _build_gui(self, name: str) -> None:
        gui = self.server.gui
        gui.add_markdown(f"**{name}**")
        self._batch = False
        self._sliders: dict[str, Any] = {}
        with gui.add_folder("Joints"):
            for joint, lim in self._limits.items():
                lo, hi = lim if lim is not None else (-math.pi, math.pi)
                s = gui.add_slider(
                    joint, min=lo, max=hi, step=SLIDER_STEP, initial_value=neutral(lim)
                )
                s.on_update(lambda _e: None if self._batch else self._apply())
                self._sliders[joint] = s
        if self._poses:
            with gui.add_folder("Poses"):
                for pose in self._poses:
                    gui.add_button(pose).on_click(self._pose_button(pose))
        self._frames_box: Any = gui.add_checkbox("Show link frames", initial_value=False)
        self._frames_box.on_update(lambda _e: self._update_frames())
        self._tool_text: Any = gui.add_text("Tool position [m]", initial_value="", disabled=True)
        if self._replay is not None:
            self._build_replay_gui()

    def _build_replay_gui(self) -> None:
        assert self._replay is not None
        gui = self.server.gui
        with gui.add_folder("Replay"):
            play = gui.add_button("Play / pause")
            play.on_click(lambda _e: self.play(not self._playing))
            self._speed: Any = gui.add_slider(
                "Speed", min=0.1, max=4.0, step=0.1, initial_value=1.0
            )
            self._loop: Any = gui.add_checkbox("Loop", initial_value=True)
            self._time_slider: Any = gui.add_slider(
                "Time [s]",
                min=0.0,
                max=max(self._replay.duration, 1e-3),
                step=1e-3,
                initial_value=0.0,
            )
            self._time_slider.on_update(lambda _e: self._show_time(self._time_slider.value))
            if self._ghost is not None:
                box = gui.add_checkbox("Show reference (ghost)", initial_value=True)
                box.on_update(lambda _e: self._show_time(self._time_slider.value))
                self._ghost_box = box
        self._show_time(0.0)

    def _pose_button(self, pose: str) -> Any:
        def on_click(_event: Any) -> None:
            self.apply_pose(pose)

        return on_click

    def _show_time(self, t: float) -> None:
        assert self._replay is not None
        t0 = float(self._replay.time[0]) + t
        q = {j: v for j, v in self._replay.positions_at(t0).items() if j in self._sliders}
        pose = self._replay.base_at(t0)
        if pose is not None and self._base is not None:
            self._base.position, self._base.wxyz = tuple(pose[0]), tuple(pose[1])
        self.set_configuration({j: self._in_range(j, v) for j, v in q.items()})
        if self._sensors is not None:
            self._sensors.show(t0)
        if self._ghost is not None:
            ref = self._replay.reference_at(t0)
            visible = ref is not None and bool(self._ghost_box.value)
            if ref is not None:
                self._ghost.update_cfg(self._cfg_array({**self.configuration(), **ref}))
            self._ghost.show_visual = visible

    def _in_range(self, joint: str, value: float) -> float:
        """A bounded joint clipped to its limits; a continuous one (a wheel) wrapped to ±pi."""
        if self._limits[joint] is None:
            return float((value + math.pi) % (2.0 * math.pi) - math.pi)
        return float(np.clip(value, *self._range(joint)))

    def _range(self, joint: str) -> tuple[float, float]:
        lim = self._limits[joint]
        return lim if lim is not None else (-math.pi, math.pi)

    def _cfg_array(self, q: Mapping[str, float]) -> np.ndarray:
        return np.array([float(q.get(j, 0.0)) for j in self._limits])

    def _apply(self) -> None:
        """Push the slider values to the robot, the frames and the tool readout."""
        with self._lock:
            self._robot.update_cfg(self._cfg_array({n: s.value for n, s in self._sliders.items()}))
            tip = tool_position(self._urdf, self._tool)
            if tip is not None and self._tool_marker is not None:
                self._tool_marker.position = tuple(tip)
                self._tool_text.value = "({:.3f}, {:.3f}, {:.3f})".format(*tip)
            self._update_frames()

    def _update_frames(self) -> None:
        with self._lock:
            visible = bool(self._frames_box.value)
            for link, frame in self._frames.items():
                T = self._urdf.get_transform(link, self._urdf.base_link)
                frame.position = tuple(T[:3, 3])
                x, y, z, w = matrix_quaternion(T[:3, :3])
                frame.wxyz = (w, x, y, z)
                frame.visible = visible

    def _play_loop(self) -> None:
        assert self._replay is not None
        last = time.monotonic()
        while not self._stop.wait(1.0 / FRAME_RATE):
            now = time.monotonic()
            dt, last = now - last, now
            if not self._playing:
                continue
            t = self._time_slider.value + dt * float(self._speed.value)
            if t > self._replay.duration:
                t = 0.0 if self._loop.value else self._replay.duration
                self._playing = bool(self._loop.value)
            self._time_slider.value = t
