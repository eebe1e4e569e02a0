"""The planning benchmark's scenes, queries and peers (bench/bench_plan.py runs them).

Scene kinds (bench/scenes/, written for this benchmark): an open table, a cabinet of
shelves, a cluttered bin, a wall with a 26 x 40 cm slot. A query is a pair of seeded random
configurations of the Panda that both collision models call free, with the tool point where
the kind makes the task (near the table; in a compartment; in the bin; one end beyond the
wall, the other before it), and whose straight joint-space segment collides: no query is
solved by the straight line.

Peers: roboplan 0.7.0 (C++ RRT-Connect + its PathShortcutter, on the same URDF, SRDF and
obstacles) and the floor (OMPL RRT-Connect with a plain Python validity callback over every
enabled pair, as a user of the Python bindings would write it, + OMPL's vertex reduction).
"""

from __future__ import annotations

import math
import sys
import sysconfig
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from armcli.io.packages import PackageLookup  # noqa: E402
from armcli.io.scene import Scene  # noqa: E402
from armcli.plan.api import PlanningContext  # noqa: E402
from armcli.plan.ik import tool_pose  # noqa: E402
from armcli.plan.inputs import Loaded, load_context  # noqa: E402
from armcli.urdf.source import read_robot  # noqa: E402

SCENES = ROOT / "bench" / "scenes"
ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share" / "example-robot-data"
PANDA = ERD / "robots" / "panda_description"
ARM = [f"panda_joint{i}" for i in range(1, 8)]


@dataclass(frozen=True)
class Arm:
    """A robot of example-robot-data: its URDF, SRDF and planned joints."""

    urdf: Path
    srdf: Path
    joints: list[str]


PANDA_ARM = Arm(PANDA / "urdf" / "panda.urdf", PANDA / "srdf" / "panda.srdf", ARM)
UR = ERD / "robots" / "ur_description"
# the sanity check on an arm nobody here tuned for (bench_plan.other_arm)
UR5_ARM = Arm(UR / "urdf" / "ur5_joint_limited_robot.urdf", UR / "srdf" / "ur5.srdf",
              ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
               "wrist_2_joint", "wrist_3_joint"])  # fmt: skip
TIMEOUT_S = 1.0
STEP = 0.02  # [rad] collision-check step of every planner
Point = Callable[[np.ndarray], bool]


def _in_box(centre: tuple[float, float, float], yaw: float, half: tuple[float, ...]) -> Point:
    """Whether a point [m] is inside a box turned by `yaw` [rad] about z."""
    c, s = math.cos(yaw), math.sin(yaw)

    def inside(p: np.ndarray) -> bool:
        d = p - np.array(centre)
        local = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]])
        return bool(np.all(np.abs(local) <= np.array(half)))

    return inside


@dataclass(frozen=True)
class Kind:
    """A scene kind: its file and where the tool point is at the two ends of a query."""

    name: str
    scene: str
    first: Point
    second: Point


def _anywhere(p: np.ndarray) -> bool:
    return True


KINDS = (
    Kind("open table", "panda_open_table.yaml", lambda p: p[2] < 0.3, lambda p: p[2] < 0.3),
    # bench/scenes/panda_cabinet.yaml: its compartments, inside the boards and sides
    Kind("shelf", "panda_cabinet.yaml",
         _in_box((0.62, 0.25, 0.535), math.radians(30), (0.15, 0.39, 0.51)), _anywhere),
    # bench/scenes/panda_bin.yaml: inside the bin's walls, below its rim
    Kind("cluttered bin", "panda_bin.yaml",
         _in_box((0.5, 0.05, 0.13), 0.0, (0.19, 0.24, 0.12)), _anywhere),
    # bench/scenes/panda_slot.yaml: the wall's faces are at x = 0.44 and 0.46
    Kind("slot in a wall", "panda_slot.yaml", lambda p: p[0] > 0.47, lambda p: p[0] < 0.43),
)  # fmt: skip


def panda_context(scene: Path | None, arm: Arm = PANDA_ARM) -> Loaded:
    """The Panda (or `arm`) with its SRDF, the arm joints planned, in `scene`."""
    return load_context(
        read_robot(arm.urdf),
        srdf=arm.srdf,
        scene=scene,
        joints=arm.joints,
        search=PackageLookup({"example-robot-data": ERD}),
    )


def queries(kind: Kind, ctx: PlanningContext, rb: Roboplan, count: int, seed: int
            ) -> list[tuple[np.ndarray, np.ndarray]]:  # fmt: skip
    """Seeded start/goal pairs of `kind` (see the module docstring)."""
    rng = np.random.default_rng(seed)
    r, ck = ctx.robot, ctx.checker
    ends: tuple[list[np.ndarray], list[np.ndarray]] = ([], [])
    out: list[tuple[np.ndarray, np.ndarray]] = []
    while len(out) < count:
        x = rng.uniform(r.lower, r.upper)
        if ck.first_collision(x, every_pair=True) is not None or rb.has(x):
            continue
        p = tool_pose(r, x)[0]
        for k, test in enumerate((kind.first, kind.second)):
            if test(p) and len(ends[k]) <= len(ends[1 - k]):
                ends[k].append(x)
                break
        if ends[0] and ends[1]:
            a, b = ends[0].pop(), ends[1].pop()
            if not ck.motion_free(a, b, STEP):  # the straight segment collides
                out.append((a, b))
    return out


class Roboplan:
    """roboplan's scene with the same URDF, SRDF and obstacles, and its RRT-Connect."""

    def __init__(self, obstacles: Scene, arm: Arm = PANDA_ARM) -> None:
        from roboplan.core import (
            Box,
            Cylinder,
            PathShortcutter,
            PathShortcuttingOptions,
            Sphere,
            loadUrdfSceneDescription,
        )
        from roboplan.core import Scene as RScene
        from roboplan.rrt import RRT, RRTOptions

        self.joints = arm.joints
        desc = loadUrdfSceneDescription(str(arm.urdf), [str(ERD.parent)])
        self.scene = RScene("robot", desc)
        self.scene.importSrdf(arm.srdf.read_text())
        self.scene.addGroup("arm", arm.joints)
        color = np.array([0.5, 0.5, 0.5, 1.0])
        shapes = {"box": lambda d: Box(*d), "sphere": lambda d: Sphere(d[0]),
                  "cylinder": lambda d: Cylinder(d[1], d[0])}  # fmt: skip
        names = [f"{o.id}_{k}" for o in obstacles.objects for k in range(len(o.shapes))]
        for obj in obstacles.objects:
            for k, shape in enumerate(obj.shapes):
                adder = getattr(self.scene, f"add{shape.kind.capitalize()}Geometry")
                adder(f"{obj.id}_{k}", "universe", shapes[shape.kind](shape.dimensions),
                      np.asfortranarray(shape.T_frame_shape), color)  # fmt: skip
        pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1 :]]
        if pairs:  # obstacles touching each other are no collision of the robot's
            self.scene.setCollisions(pairs, False)
        opts = RRTOptions(group_name="arm", rrt_connect=True, max_planning_time=TIMEOUT_S,
                          max_nodes=100000, collision_check_step_size=STEP)  # fmt: skip
        self.rrt = RRT(self.scene, opts)
        self.short = PathShortcutter(
            self.scene, PathShortcuttingOptions(group_name="arm", max_step_size=STEP)
        )
        self.full = self.scene.getCurrentJointPositions()
        self.idx = self.scene.getJointPositionIndices(arm.joints)

    def has(self, x: np.ndarray) -> bool:
        q = self.full.copy()
        q[self.idx] = x
        return bool(self.scene.hasCollisions(q))

    def plan(self, a: np.ndarray, b: np.ndarray, seed: int) -> tuple[float, np.ndarray | None]:
        """(planning + shortcutting time [s], path or None)."""
        from roboplan.core import JointConfiguration

        self.rrt.setRngSeed(seed)
        t0 = time.perf_counter()
        try:
            path = self.rrt.plan(JointConfiguration(self.joints, a),
                                 JointConfiguration(self.joints, b))  # fmt: skip
        except RuntimeError:  # roboplan 0.7.0 raises on its time limit
            path = None
        if path is None or not path.positions:
            return time.perf_counter() - t0, None
        path = self.short.shortcut(path)
        dt = time.perf_counter() - t0
        return dt, np.array([p for p in path.positions])


def floor_plan(
    ctx: PlanningContext, a: np.ndarray, b: np.ndarray, seed: int
) -> tuple[float, np.ndarray | None]:
    """OMPL RRT-Connect, a plain Python validity callback over every enabled pair."""
    import ompl.base as ob
    import ompl.geometric as og
    import ompl.util as ou
    import pinocchio as pin

    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    ou.RNG.setSeed(seed)
    ck, r = ctx.checker, ctx.robot
    n = len(a)
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for i in range(n):
        bounds.setLow(i, float(r.lower[i]))
        bounds.setHigh(i, float(r.upper[i]))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    data, gdata = r.model.createData(), pin.GeometryData(ck.gmodel)

    def valid(s: Any) -> bool:
        q = r.q([s[i] for i in range(n)])
        return not pin.computeCollisions(r.model, data, ck.gmodel, gdata, q, True)

    setup.setStateValidityChecker(valid)
    info = setup.getSpaceInformation()
    info.setStateValidityCheckingResolution(STEP / space.getMaximumExtent())
    s0, s1 = space.allocState(), space.allocState()
    for i in range(n):
        s0[i], s1[i] = float(a[i]), float(b[i])
    setup.setStartAndGoalStates(s0, s1)
    setup.setPlanner(og.RRTConnect(info))
    t0 = time.perf_counter()
    setup.solve(TIMEOUT_S)
    path = None
    if setup.haveExactSolutionPath():
        p = setup.getSolutionPath()
        og.PathSimplifier(info).reduceVertices(p)
        path = np.array([[p.getState(k)[i] for i in range(n)] for k in range(p.getStateCount())])
    dt = time.perf_counter() - t0
    setup.clear()
    return dt, path
