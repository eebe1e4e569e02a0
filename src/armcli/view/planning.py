"""The planning panel's logic, without a browser: start, goal, live IK, plan, execute, save.

RViz's MotionPlanning panel on armcli's plan library: the goal comes from a named pose or
from dragging the tool point (inverse kinematics seeded at the current goal, so the arm
follows the hand smoothly); **Plan** calls `plan.api.plan_motion` (a certified trajectory
or a one-line reason); **Execute** runs the plan through `plan.execute` (simulate's
library) and keeps the simulated states to replay; **Save** writes the trajectory YAML
into the save directory only, atomically. The viser GUI (view.panel) is a thin layer
over `PlanningSession`, which the tests drive directly.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

import numpy as np

from armcli.defaults import MAX_COORDINATE_M
from armcli.errors import BuildError, InputError, OutputRefusedError, PlanningError
from armcli.io.files import write_file_atomic
from armcli.io.outdir import check_output_file, relative_inside
from armcli.io.scene import Scene, Shape
from armcli.plan.api import PlanningContext, PlanOptions, PlanResult, plan_motion, values
from armcli.plan.execute import Execution, execute
from armcli.plan.ik import solve_ik, tool_pose
from armcli.plan.inputs import load_context
from armcli.sim.options import SimOptions
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile

LIVE_IK_ATTEMPTS = 16  # seeded at the goal, then restarts (Panda: ~0.1 s; 4 miss by singularities)
TRAIL_POSES = 7  # ghost poses drawn along a plan, both ends included
TRAIL_POINTS = 60  # tool-point samples of the drawn path
SAVE_SUFFIXES = (".yaml", ".yml")
NAME_MAX = 255  # [bytes] one file name (Linux's NAME_MAX)
MAX_SAVE_NAME_BYTES = 1024  # a name with its subdirectories


@dataclass(frozen=True)
class IkOutcome:
    """What a drag of the tool point gave: joint values, or None and how close IK came."""

    x: np.ndarray | None
    distance: float  # [m] tool point to target at the best attempt

    def text(self) -> str:
        """One status line."""
        if self.x is not None:
            return "goal: tool point reached"
        return f"goal unchanged: no collision-free IK solution; closest {self.distance:.3g} m away"


@dataclass(frozen=True)
class Trail:
    """Ghost poses along a plan (planned-joint values) and the tool point's path [m]."""

    poses: tuple[np.ndarray, ...]
    tool_path: np.ndarray  # (TRAIL_POINTS, 3) in the root frame


@dataclass(frozen=True)
class ObstacleMesh:
    """One scene shape as triangles in the root frame, to draw."""

    id: str
    vertices: np.ndarray  # (V, 3) [m]
    faces: np.ndarray  # (F, 3)


class PlanningSession:
    """Start and goal of the planned joints, the last plan and its execution.

    Execute simulates each plan's document on `robot_file` (read once, not again).
    `save_dir`: the one directory Save writes into.
    """

    def __init__(
        self,
        context: PlanningContext,
        robot_file: RobotFile,
        *,
        scene: Scene | None = None,
        search: MeshSearch | None = None,
        save_dir: Path = Path("."),
        options: PlanOptions | None = None,
    ) -> None:
        self.context, self.robot_file = context, robot_file
        self.scene = scene or Scene()
        self._search = search
        self.save_dir = Path(save_dir)
        self._written: dict[str, tuple[int, ...]] = {}  # path -> _identity of what Save wrote
        self._options = options or PlanOptions()
        robot = context.robot
        home = robot.pose("home") if "home" in robot.poses else self.neutral()
        self.start, self.goal = home.copy(), home.copy()
        self.result: PlanResult | None = None
        self.reason: str | None = None
        self.execution: Execution | None = None

    # -- what the robot offers -------------------------------------------------------------
    @property
    def joints(self) -> tuple[str, ...]:
        """The planned joints, in plan order."""
        return self.context.robot.joints

    @property
    def pose_names(self) -> tuple[str, ...]:
        """Named poses: the spec's `poses` or the SRDF's group states."""
        return tuple(self.context.robot.poses)

    def neutral(self) -> np.ndarray:
        """Each planned joint where it rests (`Robot.rest`: 0, else the middle of its range)."""
        robot = self.context.robot
        return np.array([robot.robot.rest(j) for j in robot.joints])

    def as_dict(self, x: np.ndarray) -> dict[str, float]:
        """Planned joint values by name."""
        return {j: float(v) for j, v in zip(self.joints, x, strict=True)}

    def from_dict(self, q: Mapping[str, float]) -> np.ndarray:
        """Planned joint values from a configuration by name (missing: the start's)."""
        return values(
            self.context, [q.get(j, s) for j, s in zip(self.joints, self.start, strict=True)], "q"
        )

    def pose(self, name: str) -> np.ndarray:
        """Planned joint values of a named pose (InputError naming the valid ones)."""
        return self.context.robot.pose(name)

    def tool(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tool point [m] and tool link rotation in the root frame at planned values `x`."""
        return tool_pose(self.context.robot, np.asarray(x, dtype=float))

    # -- start and goal ----------------------------------------------------------------
    def set_start(self, x: Sequence[float] | np.ndarray) -> None:
        """A new start; the last plan no longer applies."""
        self.start = values(self.context, x, "start")
        self._forget()

    def set_goal(self, x: Sequence[float] | np.ndarray) -> None:
        """A new goal; the last plan no longer applies."""
        self.goal = values(self.context, x, "goal")
        self._forget()

    def drag_goal(self, xyz: Sequence[float], rotation: np.ndarray | None = None) -> IkOutcome:
        """Move the goal so the tool point reaches `xyz` [m] (and `rotation`), collision-free.

        Seeded at the current goal; without a solution the goal stays where it was.
        """
        checker = self.context.checker
        target = np.asarray(xyz, dtype=float)
        if target.shape != (3,) or not np.all(np.abs(target) <= MAX_COORDINATE_M):
            return IkOutcome(None, math.inf)  # a client's 1e308 would overflow in IK
        res = solve_ik(
            self.context.robot,
            target,
            rotation,
            seed_x=self.goal,
            seed=self._options.seed,
            free=lambda x: checker.first_collision(x, every_pair=True) is None,
            attempts=LIVE_IK_ATTEMPTS,
        )
        if res.x is not None:
            self.set_goal(res.x)
        return IkOutcome(res.x, res.distance)

    def _forget(self) -> None:
        self.result, self.reason, self.execution = None, None, None

    # -- plan, execute, save -----------------------------------------------------------
    def plan(self) -> PlanResult | None:
        """Plan from start to goal; None and `reason` (one line) when no certified motion."""
        self._forget()
        try:
            self.result = plan_motion(self.context, self.start, self.goal, self._options)
        except PlanningError as exc:
            self.reason = exc.reason
        return self.result

    def trail(self, poses: int = TRAIL_POSES, points: int = TRAIL_POINTS) -> Trail:
        """Ghost poses evenly spaced in time along the last plan, and the tool point's path."""
        if self.result is None:
            raise PlanningError("no-plan", "nothing planned yet: click Plan first")
        timed = self.result.timed

        def at(t: float) -> np.ndarray:
            return np.array(
                [np.interp(t, timed.times, timed.positions[:, i]) for i in range(len(self.joints))]
            )

        t0, t1 = float(timed.times[0]), float(timed.times[-1])
        ghosts = tuple(at(t) for t in np.linspace(t0, t1, poses))
        path = np.array([self.tool(at(t))[0] for t in np.linspace(t0, t1, points)])
        return Trail(ghosts, path)

    def execute(self) -> Execution:
        """Simulate the last plan as `simulate --trajectory` runs it; its states replay."""
        if self.result is None:
            raise PlanningError("no-plan", "nothing planned yet: click Plan first")
        opts = SimOptions(message=self.result.document.decode("utf-8"))
        try:
            self.execution = execute(self.robot_file, opts, self._search)
        except InputError as exc:
            if exc.field not in ("SimOptions.kp", "SimOptions.kd"):
                raise
            raise InputError(
                "no PD gains to simulate with: Execute runs a spec's control.gains; "
                "`armcli import` turns this URDF into a spec that has them",
                field="execute",
            ) from None
        return self.execution

    def save_path(self, name: str) -> Path:
        """Where Save writes `name`: inside `save_dir` only, a .yaml file, never through a link.

        A name is text from the page: control characters (NUL included) and names longer
        than a file system takes are refused here, as one line (issue 42: they were
        exceptions the panel never answered).
        """
        name = name.strip()
        if any(ord(c) < 32 or ord(c) == 127 for c in name):
            raise OutputRefusedError(
                "a file name cannot hold control characters or NUL", field="save"
            )
        try:
            parts = [len(os.fsencode(p)) for p in PurePosixPath(name).parts]
        except UnicodeError:
            raise OutputRefusedError("the file name is not valid text", field="save") from None
        if sum(parts) > MAX_SAVE_NAME_BYTES or any(n > NAME_MAX for n in parts):
            raise OutputRefusedError(
                f"the file name is too long ({len(name)} characters)", field="save"
            )
        rel = relative_inside(name)
        if Path(name).suffix not in SAVE_SUFFIXES:
            raise OutputRefusedError(
                f"{name!r}: a trajectory file ends in .yaml or .yml", field="save"
            )
        root = Path(os.path.realpath(self.save_dir))
        path = root / rel
        if Path(os.path.realpath(path)) != path:  # a link could lead anywhere
            raise OutputRefusedError(f"{name!r} goes through a symbolic link", field="save")
        check_output_file(path, "save")
        return path

    def save(self, name: str, *, overwrite: bool = False) -> Path:
        """Write the last plan's JointTrajectory YAML as `name` in the save directory.

        A file this session did not write itself is replaced only with `overwrite` (the
        panel's confirmation), so a stray click never replaces the user's own file.
        """
        if self.result is None:
            raise PlanningError("no-plan", "nothing planned yet: click Plan first")
        path = self.save_path(name)
        if os.path.lexists(path) and not overwrite and not self._wrote(path):
            raise OutputRefusedError(
                f"{name.strip()!r} exists and this viewer did not write it; "
                "tick Overwrite to replace it",
                field="save",
            )
        try:
            written = write_file_atomic(path, self.result.document)
            st = os.stat(written)
        except OSError as exc:
            raise BuildError(f"{path}: cannot write: {exc.strerror}") from None
        self._written[str(written)] = _identity(st)
        return written

    def _wrote(self, path: Path) -> bool:
        """Whether `path` is still the file this session's Save wrote there, unchanged."""
        try:
            st = os.stat(path)
        except OSError:
            return False
        return self._written.get(str(path)) == _identity(st)

    def obstacles(self) -> list[ObstacleMesh]:
        """The scene's shapes as meshes in the root frame (link-fixed ones at the start pose)."""
        robot = self.context.robot
        q = robot.q(self.start)
        out = []
        for obj in self.scene.objects:
            T = np.eye(4)
            if obj.frame:
                T = robot.robot.frame_pose(obj.frame, q)
            for shape in obj.shapes:
                v, f = _triangles(shape)
                M = T @ shape.T_frame_shape
                out.append(ObstacleMesh(obj.id, v @ M[:3, :3].T + M[:3, 3], f))
        return out


def _identity(st: os.stat_result) -> tuple[int, ...]:
    """A file's identity and version: device, inode, size, modification time [ns]."""
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


def _triangles(shape: Shape) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of a SolidPrimitive (cylinder and cone: [height, radius]) or mesh."""
    import trimesh

    d = shape.dimensions
    if shape.kind == "box":
        m = trimesh.creation.box(extents=d)
    elif shape.kind == "sphere":
        m = trimesh.creation.icosphere(subdivisions=3, radius=d[0])
    elif shape.kind == "cylinder":
        m = trimesh.creation.cylinder(radius=d[1], height=d[0])
    elif shape.kind == "cone":  # SolidPrimitive's cone is centred on its axis' midpoint
        m = trimesh.creation.cone(radius=d[1], height=d[0])
        m.apply_translation((0.0, 0.0, -d[0] / 2))
    else:
        assert shape.vertices is not None and shape.triangles is not None
        return np.asarray(shape.vertices, dtype=float), np.asarray(shape.triangles)
    return np.asarray(m.vertices, dtype=float), np.asarray(m.faces)


def load_session(
    robot_file: RobotFile,
    *,
    srdf: Path | None = None,
    scene: Path | None = None,
    joints: Sequence[str] | None = None,
    search: MeshSearch | None = None,
    save_dir: Path = Path("."),
    group: str | None = None,
) -> PlanningSession:
    """A session for a robot file, its SRDF (a URDF's) and a scene file: what `view` builds.

    `joints` or `group` (a planning group of the SRDF) names the planned joints.
    """
    loaded = load_context(
        robot_file, srdf=srdf, scene=scene, joints=joints, search=search, group=group
    )
    return PlanningSession(
        loaded.context, robot_file, scene=loaded.scene, search=search, save_dir=save_dir
    )
