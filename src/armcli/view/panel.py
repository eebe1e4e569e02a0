"""The planning panel in the browser: viser widgets over a `PlanningSession` (view.planning).

Like RViz's MotionPlanning panel: the goal is an orange ghost of the moving links,
placed by a named pose or by dragging the tool point's transform controls (live IK);
**Plan** draws the motion as a trail of translucent ghost poses and the tool point's
path, or shows why there is none; **Execute** simulates the plan and replays the
simulated motion on the robot; **Save** writes the trajectory YAML. Every widget
callback goes through one lock, so a click during a plan waits instead of interleaving.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.errors import ArmcliError, InputError
from armcli.robot.frames import matrix_quaternion, quaternion_matrix
from armcli.urdf.meshes import MeshSearch
from armcli.view.browser import FRAME_RATE, moving_parts
from armcli.view.planning import PlanningSession
from armcli.view.png import load_urdf

if TYPE_CHECKING:
    from armcli.plan.api import PlanResult
    from armcli.view.browser import Viewer

GOAL_RGBA = (1.0, 0.5, 0.05, 0.45)  # RViz's goal state: orange
TRAIL_RGBA = (0.85, 0.2, 0.75, 0.22)  # translucent magenta ghosts along the plan
PATH_RGB = (200, 30, 170)  # the tool point's planned path
OBSTACLE_RGB = (150, 150, 165)  # the scene's collision objects
PATH_THICKNESS = 0.006  # [m]
CAMERA_BACK = 1.2  # the first view steps back this much to take in the poses' reach
HANDLE_SCALE = 0.15  # [m] size of the tool point's drag handles
CURRENT = "<current>"  # start: where the robot is now
DRAGGED = "<dragged>"  # goal: wherever the tool point was dragged


class PlanningPanel:
    """Adds the Planning folder, the goal ghost, the drag handles and the trail to a Viewer."""

    def __init__(
        self,
        viewer: Viewer,
        session: PlanningSession,
        urdf_xml: str,
        *,
        source: str = "<urdf>",
        mesh_dir: str | Path | None = None,
        search: MeshSearch | None = None,
    ) -> None:
        self.viewer, self.session = viewer, session
        # one yourdfpy model for every ghost: each ghost poses it and reads it at once
        self._ghost_urdf = load_urdf(
            moving_parts(urdf_xml, session.joints, source), source, mesh_dir, search
        )
        self._lock = threading.RLock()
        self._quiet = False  # set while the panel moves its own widgets
        self._trail: list[Any] = []
        self._replayer: threading.Thread | None = None
        self._stop = threading.Event()
        self._node = f"{viewer.root}/plan"  # under the base during a drive's replay
        self._goal_ghost = self._ghost(f"{self._node}/goal", GOAL_RGBA)
        self._path: Any = None
        self._build_gui()
        self._build_handle()
        self._frame_camera()
        # a drive's replay carries the scene with the robot (it is the arm's, in the base
        # frame); the mobile base panel's scene is the room, which stays (view.basepanel)
        scene = "/room" if viewer.MOBILE else f"{self._node}/scene"
        for k, ob in enumerate(session.obstacles()):
            viewer.server.scene.add_mesh_simple(
                f"{scene}/{k}", ob.vertices, ob.faces, color=OBSTACLE_RGB, opacity=0.6
            )
        self._show_goal()

    # -- API the GUI and the tests share ---------------------------------------------------
    @property
    def status(self) -> str:
        """The one status line shown under the buttons."""
        return str(self._status.content)

    def replaying(self) -> bool:
        """Whether an executed motion is being replayed on the robot."""
        return self._replayer is not None and self._replayer.is_alive()

    def trail_visible(self) -> bool:
        """Whether a plan's ghost trail is drawn."""
        return bool(self._trail) and bool(self._trail[0].show_visual)

    def choose_start(self, name: str) -> None:
        """Start at a named pose, or `<current>` (the robot's pose when Plan is clicked)."""
        self._start_box.value = name

    def choose_goal(self, name: str) -> None:
        """Goal at a named pose."""
        self._goal_box.value = name

    def drag(self, xyz: tuple[float, float, float], wxyz: tuple[float, ...] | None = None) -> None:
        """What dragging the handle to `xyz` [m] (and `wxyz`) does: live IK to a new goal."""
        with self._lock:
            rotation = None
            if wxyz is not None and len(self.session.joints) >= 6:
                w, x, y, z = (float(v) for v in wxyz)
                rotation = quaternion_matrix((x, y, z, w))
            outcome = self.session.drag_goal(xyz, rotation)
            self._set_status(outcome.text())
            if outcome.x is not None:
                self._quietly(lambda: setattr(self._goal_box, "value", DRAGGED))
                self._hide_trail()
            self._show_goal(move_handle=False)  # the handle stays under the pointer

    def plan(self) -> bool:
        """Plan from the chosen start to the goal; draw the trail or show the reason."""
        with self._lock:
            self._buttons(busy=True)
            try:
                self._set_status("planning...")
                result, reason = self._plan()
                if result is None:
                    self._hide_trail()
                    self._set_status(f"no plan: {reason}")
                    return False
                self._draw_trail()
                self._set_status(
                    f"planned: {result.duration_s:.2f} s, {len(result.path)} waypoints, "
                    f"{result.planning_time_s * 1e3:.0f} ms; certified"
                )
                return True
            finally:
                self._buttons(busy=False)

    def _plan(self) -> tuple[PlanResult | None, str | None]:
        try:
            if self.viewer.MOBILE:  # the arm is planned with its base at the room's origin
                from armcli.view.basepanel import MobileViewer

                assert isinstance(self.viewer, MobileViewer)
                self.viewer.home()
            if self._start_box.value == CURRENT:
                self.session.set_start(self.session.from_dict(self.viewer.configuration()))
            return self.session.plan(), self.session.reason
        except ArmcliError as exc:  # e.g. a current pose the planner cannot take
            return None, str(exc)

    def execute(self, *, wait: bool = False) -> bool:
        """Simulate the plan, then replay it on the robot; False with a reason if broken."""
        with self._lock:
            self._buttons(busy=True)
            try:
                self._set_status("simulating...")
                done = self.session.execute()
            except ArmcliError as exc:
                self._set_status(f"not executed: {exc}")
                return False
            finally:
                self._buttons(busy=False)
            err = max((m.max_error for m in done.metrics), default=0.0)
            head = "executed" if not done.broken else "executed, broken: " + done.problems[0]
            self._set_status(f"{head}; max tracking error {err:.4f} rad")
        self._start_replay()
        if wait and self._replayer is not None:
            self._replayer.join()
        return not done.broken

    def save(self) -> Path | None:
        """Write the plan's trajectory YAML under the name in the File box.

        Over a file the viewer did not write only with Overwrite ticked (unticked after).
        """
        with self._lock:
            try:
                overwrite = bool(self._overwrite_box.value)
                path = self.session.save(str(self._file_box.value), overwrite=overwrite)
            except ArmcliError as exc:
                self._set_status(f"not saved: {exc}")
                return None
            except Exception as exc:  # the page's input must never kill the answer
                self._set_status(f"not saved: {type(exc).__name__}: {exc}")
                return None
            self._quietly(lambda: setattr(self._overwrite_box, "value", False))
            self._set_status(f"wrote {path}")
            return path

    def close(self) -> None:
        """Stop a running replay (before the viewer closes)."""
        self._stop_replay()

    def _stop_replay(self) -> None:
        self._stop.set()
        if self._replayer is not None:
            self._replayer.join(timeout=2.0)
        self._stop = threading.Event()

    # -- widgets -------------------------------------------------------------------------
    def _build_gui(self) -> None:
        gui, names = self.viewer.server.gui, self.session.pose_names
        with gui.add_folder("Planning"):
            self._start_box: Any = gui.add_dropdown(
                "Start", (CURRENT, *names), initial_value=CURRENT
            )
            goal = next((n for n in names if n != "home"), DRAGGED)
            self._goal_box: Any = gui.add_dropdown("Goal", (*names, DRAGGED), initial_value=goal)
            self._plan_button: Any = gui.add_button("Plan")
            self._execute_button: Any = gui.add_button("Execute", disabled=True)
            self._file_box: Any = gui.add_text("File", initial_value="plan.yaml")
            self._overwrite_box: Any = gui.add_checkbox("Overwrite", initial_value=False)
            self._save_button: Any = gui.add_button("Save", disabled=True)
            self._status: Any = gui.add_markdown("drag the tool point or pick a goal, then Plan")
        self._start_box.on_update(lambda _e: self._on_start())
        self._goal_box.on_update(lambda _e: self._on_goal())
        self._plan_button.on_click(_click(self.plan))
        self._execute_button.on_click(_click(self.execute))
        self._save_button.on_click(_click(self.save))
        if goal != DRAGGED:
            self.session.set_goal(self.session.pose(goal))

    def _build_handle(self) -> None:
        few = len(self.session.joints) < 6  # position goals only: no rotation rings
        self._handle: Any = self.viewer.server.scene.add_transform_controls(
            f"{self._node}/target", scale=HANDLE_SCALE, disable_rotations=few, depth_test=False
        )

        def on_drag(_event: Any) -> None:
            if not self._quiet:
                self.drag(tuple(self._handle.position), tuple(self._handle.wxyz))

        self._handle.on_update(on_drag)

    def _on_start(self) -> None:
        if self._quiet:
            return
        with self._lock:
            name = str(self._start_box.value)
            if name != CURRENT:
                x = self._named(name)
                if x is None:
                    return
                self.session.set_start(x)
                self.viewer.set_configuration(self.session.as_dict(self.session.start))
            self._hide_trail()

    def _on_goal(self) -> None:
        if self._quiet or self._goal_box.value == DRAGGED:
            return
        with self._lock:
            x = self._named(str(self._goal_box.value))
            if x is None:
                return
            self.session.set_goal(x)
            self._hide_trail()
            self._show_goal()

    def _named(self, name: str) -> np.ndarray | None:
        """A named pose's values, or None and the reason in the status line.

        A page may send any name, not only the dropdown's (issue 42: a traceback before).
        """
        try:
            return self.session.pose(name)
        except ArmcliError as exc:
            self._set_status(f"not changed: {exc.message if isinstance(exc, InputError) else exc}")
            return None

    def _buttons(self, *, busy: bool) -> None:
        """Plan while idle; Execute and Save once there is a plan."""
        self._plan_button.disabled = busy
        done = self.session.result is not None
        self._execute_button.disabled = busy or not done
        self._save_button.disabled = busy or not done

    def _set_status(self, text: str) -> None:
        self._status.content = text

    def _quietly(self, change: Any) -> None:
        self._quiet = True
        try:
            change()
        finally:
            self._quiet = False

    # -- scene ---------------------------------------------------------------------------
    def _frame_camera(self) -> None:
        """Aim the first view at the robot and the tool points of its named poses."""
        cam = self.viewer.server.initial_camera
        look, eye = np.asarray(cam.look_at, dtype=float), np.asarray(cam.position, dtype=float)
        names = self.session.pose_names
        pts = np.array([look, *(self.session.tool(self.session.pose(n))[0] for n in names)])
        centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
        cam.look_at = centre
        cam.position = centre + CAMERA_BACK * (eye - look)

    def _ghost(self, root: str, rgba: tuple[float, float, float, float]) -> Any:
        from viser.extras import ViserUrdf

        return ViserUrdf(
            self.viewer.server, self._ghost_urdf, root_node_name=root, mesh_color_override=rgba
        )

    def _cfg(self, x: np.ndarray) -> np.ndarray:
        """A ghost's configuration: the viewer's joints, planned ones at `x`."""
        q = {**self.viewer.configuration(), **self.session.as_dict(x)}
        return np.array([q[j] for j in self.viewer.joint_names])

    def _show_goal(self, *, move_handle: bool = True) -> None:
        self._goal_ghost.update_cfg(self._cfg(self.session.goal))
        if move_handle:
            p, R = self.session.tool(self.session.goal)
            self._quietly(lambda: self._place_handle(p, R))
        self._buttons(busy=False)

    def _place_handle(self, p: np.ndarray, R: np.ndarray) -> None:
        x, y, z, w = matrix_quaternion(R)
        self._handle.position = (float(p[0]), float(p[1]), float(p[2]))
        self._handle.wxyz = (w, x, y, z)

    def _draw_trail(self) -> None:
        trail = self.session.trail()
        while len(self._trail) < len(trail.poses):
            self._trail.append(self._ghost(f"{self._node}/trail/{len(self._trail)}", TRAIL_RGBA))
        for ghost, x in zip(self._trail, trail.poses, strict=False):
            ghost.update_cfg(self._cfg(x))
            ghost.show_visual = True
        self._path = self.viewer.server.scene.add_spline_catmull_rom(
            f"{self._node}/path", trail.tool_path, color=PATH_RGB, thickness=PATH_THICKNESS
        )

    def _hide_trail(self) -> None:
        for ghost in self._trail:
            ghost.show_visual = False
        if self._path is not None:
            self._path.visible = False

    def _start_replay(self) -> None:
        done = self.session.execution
        if done is None or done.states is None:
            return
        self._stop_replay()  # a second Execute restarts the replay
        states, joints, stop = done.states, self.session.joints, self._stop
        lo = dict(zip(joints, self.session.context.robot.lower, strict=True))
        hi = dict(zip(joints, self.session.context.robot.upper, strict=True))

        def play() -> None:
            t0, start = float(states.time[0]), time.monotonic()
            while True:
                t = time.monotonic() - start
                at = states.positions_at(t0 + min(t, states.duration))
                q = {j: float(np.clip(v, lo[j], hi[j])) for j, v in at.items() if j in lo}
                self.viewer.set_configuration(q)
                if t >= states.duration or stop.wait(1.0 / FRAME_RATE):
                    return

        self._replayer = threading.Thread(target=play, daemon=True)
        self._replayer.start()


def _click(action: Callable[[], object]) -> Callable[[Any], None]:
    """A button callback running `action` (its result is for the API, not the page)."""

    def on_click(_event: Any) -> None:
        action()

    return on_click
