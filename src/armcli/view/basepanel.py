"""The planning panel's mobile base in the browser: viser widgets over a `BaseSession`.

A "Mobile base" folder beside the Planning one: a target handle that goes anywhere in the
room (position only); **Plan** draws the base's path on the floor, the feasible region
(the floor positions from which the target is in reach) as points, and ghosts of the arm
along its motion at the parked pose; **Execute** runs the plan on the MuJoCo drive and
replays the whole robot: the root moves with the run's ground truth (`Viewer.set_base`),
the arm and the wheels with its joints, and leaves it parked. The scene's objects are the
room's: they stay in the world (the planning panel draws them at /room), and either
panel's Plan puts the robot back at the origin, where both plan from. One lock, as
view.panel's.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from armcli.errors import ArmcliError
from armcli.urdf.meshes import MeshSearch
from armcli.view.baseplan import BaseSession
from armcli.view.browser import FRAME_RATE, Viewer, moving_parts
from armcli.view.png import load_urdf

GHOST_RGBA = (0.2, 0.55, 0.95, 0.3)  # translucent blue arms at the parked pose
PATH_RGB = (30, 110, 220)  # the base's path on the floor
REGION_RGB = (40, 170, 70)  # where the base may stand
REGION_POINT = 0.02  # [m] drawn size of a region point
FLOOR_LIFT = 0.004  # [m] drawings sit this far above the floor (not hidden in it)
TARGET = (1.2, 0.0, 0.5)  # [m] the room target's first place: in front of the robot
HANDLE_SCALE = 0.25  # [m]


def _click(action: Callable[[], object]) -> Callable[[Any], None]:
    """A button callback running `action` (its result is for the API, not the page)."""

    def on_click(_event: Any) -> None:
        action()

    return on_click


def _yaw_wxyz(yaw: float) -> tuple[float, float, float, float]:
    return math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)


class MobileViewer(Viewer):
    """The viewer whose robot hangs from a frame the mobile base's replay moves."""

    MOBILE = True

    def set_base(self, position: ArrayLike, wxyz: ArrayLike) -> None:
        """Put the robot's root at `position` [m] turned by `wxyz` (unit quaternion)."""
        assert self._base is not None  # MOBILE: Viewer made the frame
        with self._lock:
            self._base.position, self._base.wxyz = np.asarray(position), np.asarray(wxyz)

    def home(self) -> None:
        """Put the robot back at the room's origin, where plans start (after a replay)."""
        self.set_base((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))

    def base_position(self) -> np.ndarray:
        """Where the robot's root is [m]."""
        assert self._base is not None
        return np.array(self._base.position, dtype=float)

    def in_range(self, q: Mapping[str, float]) -> dict[str, float]:
        """The viewer's joints of `q`, bounded ones clipped, continuous ones wrapped to ±pi."""
        return {j: self._in_range(j, v) for j, v in q.items() if j in self._limits}


class BasePanel:
    """Adds the Mobile base folder, the room target, the drawings and the replay."""

    def __init__(
        self,
        viewer: MobileViewer,
        session: BaseSession,
        urdf_xml: str,
        *,
        source: str = "<urdf>",
        mesh_dir: str | Path | None = None,
        search: MeshSearch | None = None,
    ) -> None:
        self.viewer, self.session = viewer, session
        self._ghost_urdf = load_urdf(
            moving_parts(urdf_xml, session.arm, source), source, mesh_dir, search
        )
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._replayer: threading.Thread | None = None
        scene = viewer.server.scene
        self._parked = scene.add_frame("/plan/parked", show_axes=False, visible=False)
        self._ghosts: list[Any] = []
        self._drawn: list[Any] = []
        gui = viewer.server.gui
        with gui.add_folder("Mobile base"):
            self._plan_button: Any = gui.add_button("Plan with the base")
            self._execute_button: Any = gui.add_button("Execute the whole robot", disabled=True)
            self._status: Any = gui.add_markdown(session.status())
        self._plan_button.on_click(_click(self.plan))
        self._execute_button.on_click(_click(self.execute))
        self._handle: Any = scene.add_transform_controls(
            "/plan/room_target", scale=HANDLE_SCALE, disable_rotations=True, depth_test=False
        )
        self._handle.position = TARGET

    @property
    def status(self) -> str:
        """The folder's status line."""
        return str(self._status.content)

    def move_target(self, xyz: tuple[float, float, float]) -> None:
        """Put the room target at xyz [m] (what dragging its handle does)."""
        self._handle.position = tuple(float(v) for v in xyz)

    def plan(self) -> bool:
        """Plan the base and the arm to the room target; draw the plan or show why none."""
        with self._lock:
            self._buttons(busy=True)
            try:
                self._status.content = "planning the base and the arm..."
                self.close()  # a replay still running
                self.viewer.home()  # the plan starts at the origin
                x, y, z = (float(v) for v in self._handle.position)
                drawing = self.session.plan_to((x, y, z))
                self._clear()
                if drawing is not None:
                    self._draw(drawing)
                self._status.content = self.session.status()
                return drawing is not None
            finally:
                self._buttons(busy=False)

    def execute(self, *, wait: bool = False) -> bool:
        """Run the plan on the MuJoCo drive, then replay the whole robot; False if it failed."""
        with self._lock:
            self._buttons(busy=True)
            try:
                self._status.content = "driving in MuJoCo..."
                done = self.session.execute()
            except ArmcliError as exc:
                self._status.content = f"not executed: {exc}"
                return False
            finally:
                self._buttons(busy=False)
            self._status.content = self.session.status()
        self._start_replay()
        if wait and self._replayer is not None:
            self._replayer.join()
        return not done.failed

    def replaying(self) -> bool:
        """Whether the executed run is being replayed."""
        return self._replayer is not None and self._replayer.is_alive()

    def close(self) -> None:
        """Stop a running replay."""
        self._stop.set()
        if self._replayer is not None:
            self._replayer.join(timeout=2.0)
        self._stop = threading.Event()

    def _buttons(self, *, busy: bool) -> None:
        self._plan_button.disabled = busy
        self._execute_button.disabled = busy or self.session.plan is None

    def _clear(self) -> None:
        for node in self._drawn:
            node.remove()
        self._drawn = []
        self._parked.visible = False

    def _draw(self, drawing: Any) -> None:
        from viser.extras import ViserUrdf

        scene = self.viewer.server.scene
        path = drawing.path + np.array([0.0, 0.0, FLOOR_LIFT])
        line = scene.add_spline_catmull_rom("/plan/base_path", path, color=PATH_RGB, thickness=0.01)
        self._drawn.append(line)
        if len(drawing.region):
            pts = np.column_stack([drawing.region, np.full(len(drawing.region), FLOOR_LIFT)])
            colours = np.tile(np.array(REGION_RGB, dtype=np.uint8), (len(pts), 1))
            self._drawn.append(
                scene.add_point_cloud(
                    "/plan/region", pts.astype(np.float32), colours, point_size=REGION_POINT
                )
            )
        x, y, yaw = drawing.parked
        self._parked.position, self._parked.wxyz = (x, y, 0.0), _yaw_wxyz(yaw)
        self._parked.visible = True
        while len(self._ghosts) < len(drawing.ghosts):
            self._ghosts.append(
                ViserUrdf(
                    self.viewer.server,
                    self._ghost_urdf,
                    root_node_name=f"/plan/parked/ghost{len(self._ghosts)}",
                    mesh_color_override=GHOST_RGBA,
                )
            )
        names = self.viewer.joint_names
        for ghost, q in zip(self._ghosts, drawing.ghosts, strict=False):
            values = {
                **self.viewer.configuration(),
                **dict(zip(self.session.arm, q.tolist(), strict=True)),
            }
            ghost.update_cfg(np.array([values.get(j, 0.0) for j in names]))

    def _start_replay(self) -> None:
        replay = self.session.replay()
        self.close()
        stop = self._stop

        def play() -> None:
            start = time.monotonic()
            while True:
                t = min(time.monotonic() - start, replay.duration)
                pose = replay.base_at(float(replay.time[0]) + t)
                if pose is not None:
                    self.viewer.set_base(pose[0], pose[1])
                at = replay.positions_at(float(replay.time[0]) + t)
                self.viewer.set_configuration(self.viewer.in_range(at))
                if t >= replay.duration or stop.wait(1.0 / FRAME_RATE):
                    return

        self._replayer = threading.Thread(target=play, daemon=True)
        self._replayer.start()
