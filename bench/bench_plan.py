"""Benchmark: `armcli plan` against roboplan 0.7.0 and a plain OMPL + Python validity check.

Run with `make bench` (or `python bench/bench_plan.py [--queries N] [--ik N]`).

1. The course arm (specs/my_robot.yaml), named pose to named pose, empty scene: median
   plan + parameterisation time (target <= 5 ms).
2. The Panda (example-robot-data, its SRDF) in the three scenes of bench/scenes/, N seeded
   random collision-free start/goal pairs each (the same for every planner):
   - armcli: plan_motion (OMPL RRT-Connect + shortcutting + TOPP-RA + certification);
     its time is planning + shortcutting + parameterisation, as `--format json` reports;
   - roboplan: RRT-Connect (C++) + its PathShortcutter, same URDF, SRDF and obstacles;
   - floor: OMPL RRT-Connect with a plain Python validity callback (Pinocchio
     computeCollisions over every enabled pair) + OMPL's shortcutPath.
   Success within 1 s, median time (armcli also without its TOPP-RA timing, which roboplan's
   figure leaves out), median path-length ratio armcli / roboplan over the
   queries both solved, and the certification's verdict on every armcli plan.
3. IK on the Panda: N random reachable poses (position and orientation), success, median time.
Not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import sysconfig
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from armcli.errors import PlanningError  # noqa: E402
from armcli.io.packages import PackageLookup  # noqa: E402
from armcli.io.scene import Scene  # noqa: E402
from armcli.plan.api import PlanningContext, PlanOptions, plan_motion  # noqa: E402
from armcli.plan.ik import solve_ik, tool_pose  # noqa: E402
from armcli.plan.inputs import Loaded, load_context  # noqa: E402
from armcli.urdf.source import read_robot  # noqa: E402

SPEC = ROOT / "specs" / "my_robot.yaml"
SCENES = sorted((ROOT / "bench" / "scenes").glob("panda_*.yaml"))
ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share" / "example-robot-data"
PANDA = ERD / "robots" / "panda_description"
ARM = [f"panda_joint{i}" for i in range(1, 8)]
TIMEOUT_S = 1.0
STEP = 0.02  # [rad] collision-check step of every planner
SEED = 0
COURSE_REPEATS = 30


def med(xs: list[float]) -> float:
    return statistics.median(xs) if xs else float("nan")


def length(path: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))


def course() -> None:
    ctx = load_context(read_robot(SPEC)).context
    r = ctx.robot
    pairs = [("home", "reach"), ("reach", "home")]
    times = []
    plan_motion(ctx, r.pose("home"), r.pose("reach"), PlanOptions())  # warm-up
    for _ in range(COURSE_REPEATS):
        for a, b in pairs:
            times.append(plan_motion(ctx, r.pose(a), r.pose(b), PlanOptions()).planning_time_s)
    print(
        f"course arm, named pose to named pose (home <-> reach), {len(times)} plans: "
        f"median plan + parameterisation {med(times) * 1e3:.2f} ms (target <= 5 ms)"
    )


def queries(ctx: PlanningContext, rb: Any, count: int, seed: int) -> list[tuple[Any, Any]]:
    """Seeded random start/goal pairs that both collision models call free."""
    rng = np.random.default_rng(seed)
    r = ctx.robot
    out: list[tuple[Any, Any]] = []
    free = []
    while len(out) < count:
        x = rng.uniform(r.lower, r.upper)
        if ctx.checker.first_collision(x, every_pair=True) is None and not rb.has(x):
            free.append(x)
        if len(free) == 2:
            out.append((free[0], free[1]))
            free = []
    return out


class Roboplan:
    """roboplan's scene with the same URDF, SRDF and obstacles, and its RRT-Connect."""

    def __init__(self, obstacles: Scene) -> None:
        from roboplan.core import (
            Box,
            Cylinder,
            PathShortcutter,
            PathShortcuttingOptions,
            Scene,
            Sphere,
            loadUrdfSceneDescription,
        )
        from roboplan.rrt import RRT, RRTOptions

        desc = loadUrdfSceneDescription(str(PANDA / "urdf" / "panda.urdf"), [str(ERD.parent)])
        self.scene = Scene("panda", desc)
        self.scene.importSrdf((PANDA / "srdf" / "panda.srdf").read_text())
        self.scene.addGroup("arm", ARM)
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
        self.idx = self.scene.getJointPositionIndices(ARM)

    def has(self, x: np.ndarray) -> bool:
        q = self.full.copy()
        q[self.idx] = x
        return bool(self.scene.hasCollisions(q))

    def plan(self, a: np.ndarray, b: np.ndarray, seed: int) -> tuple[float, np.ndarray | None]:
        from roboplan.core import JointConfiguration

        self.rrt.setRngSeed(seed)
        t0 = time.perf_counter()
        path = self.rrt.plan(JointConfiguration(ARM, a), JointConfiguration(ARM, b))
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


def panda_context(scene: Path | None) -> Loaded:
    """The Panda with its SRDF, the seven arm joints planned, in `scene`."""
    return load_context(
        read_robot(PANDA / "urdf" / "panda.urdf"),
        srdf=PANDA / "srdf" / "panda.srdf",
        scene=scene,
        joints=ARM,
        search=PackageLookup({"example-robot-data": ERD}),
    )


def panda(count: int) -> None:
    for scene in SCENES:
        loaded = panda_context(scene)
        ctx = loaded.context
        rb = Roboplan(loaded.scene)
        qs = queries(ctx, rb, count, SEED)
        ours: list[float] = []
        paths: list[float] = []
        theirs: list[float] = []
        floor: list[float] = []
        ratios: list[float] = []
        ok = [0, 0, 0]
        straight = 0
        violations = 0
        failed: dict[str, int] = {}
        cert: list[float] = []
        for k, (a, b) in enumerate(qs):
            mine = None
            try:
                res = plan_motion(ctx, a, b, PlanOptions(seed=k, timeout=TIMEOUT_S, step=STEP))
                if res.planning_time_s <= TIMEOUT_S:
                    ok[0] += 1
                    ours.append(res.planning_time_s)
                    paths.append(res.path_time_s)
                    cert.append(res.certify_time_s)
                    mine = res.path
                    straight += len(res.path) == 2
                else:
                    failed["over 1 s"] = failed.get("over 1 s", 0) + 1
            except PlanningError as exc:
                violations += exc.kind == "certify"
                failed[exc.kind] = failed.get(exc.kind, 0) + 1
            dt, path = rb.plan(a, b, k)
            if path is not None and dt <= TIMEOUT_S:
                ok[1] += 1
                theirs.append(dt)
                if mine is not None:
                    ratios.append(length(mine) / length(path))
            dt, path = floor_plan(ctx, a, b, k)
            if path is not None and dt <= TIMEOUT_S:
                ok[2] += 1
                floor.append(dt)
        name = scene.stem
        print(f"{name}: {count} queries ({straight} solved by the straight segment)")
        print(
            f"  armcli   solved {ok[0]}/{count}, median {med(ours) * 1e3:.1f} ms "
            f"(certification {med(cert) * 1e3:.0f} ms more), certification failures {violations}"
        )
        print(
            f"  armcli path alone (planning + shortcutting, as roboplan's figure): median "
            f"{med(paths) * 1e3:.1f} ms, ratio to roboplan {med(paths) / med(theirs):.2f}"
        )
        print(f"  roboplan solved {ok[1]}/{count}, median {med(theirs) * 1e3:.1f} ms")
        print(f"  floor    solved {ok[2]}/{count}, median {med(floor) * 1e3:.1f} ms")
        print(
            f"  time ratio armcli/roboplan {med(ours) / med(theirs):.2f}, armcli/floor "
            f"{med(ours) / med(floor):.2f}; path length armcli/roboplan median "
            f"{med(ratios):.2f} over {len(ratios)} queries"
        )


def ik(count: int) -> None:
    ctx = panda_context(None).context
    r = ctx.robot
    rng = np.random.default_rng(SEED)
    times, ok = [], 0
    for k in range(count):
        p, R = tool_pose(r, rng.uniform(r.lower, r.upper))
        t0 = time.perf_counter()
        res = solve_ik(r, p, R, seed=k)
        times.append(time.perf_counter() - t0)
        ok += res.x is not None
    print(
        f"IK, Panda, {count} random reachable poses: success {100 * ok / count:.1f} %, "
        f"median {med(times) * 1e3:.2f} ms (targets >= 99.5 %, <= 1 ms)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=100, help="start/goal pairs per scene")
    ap.add_argument("--ik", type=int, default=1000, help="IK poses")
    args = ap.parse_args()
    course()
    if not PANDA.is_dir():
        print("Panda: example-robot-data not installed, skipped")
        return
    ik(args.ik)
    panda(args.queries)


if __name__ == "__main__":
    main()
