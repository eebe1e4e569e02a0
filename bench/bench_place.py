"""Benchmark: base placement, `plan --base` and `--execute` against a brute-force grid.

Run with `make bench` (or `python bench/bench_place.py [--targets N] [--grid N]`).

1. `place` on the course robot (specs/my_robot.yaml) in two rooms it was not tuned for
   (bench/scenes/office.yaml, warehouse.yaml) and in an empty one: N seeded targets each,
   time per target after start-up (the robot and its collision model loaded once); beside
   it, on the first G targets, the brute-force grid (tests/plan/mobile/reference.py: every
   base pose of a 1 cm x 1 degree grid whose base-frame target is within the arm's reach
   band, judged by closed-form kinematics and numpy collision tests, then the least
   driving): median time and the ratio (target: place <= 10 ms, >= 100x faster).
2. `plan --base` (placement with the arm stowed, the base path, its timing; not the 3-D
   certification, not the arm) on 30 seeded targets per scene: median, beside the grid
   search's median for the same queries (target <= 100 ms).
3. `--execute` of a ~20 s whole-body motion (drive across the warehouse and reach onto a
   rack board): simulated seconds per CPU second (target >= 50x).
Not a test: numbers depend on the machine and its load (printed first).
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT))

from tests.plan.mobile.reference import (  # noqa: E402
    FEASIBLE,
    L1,
    L2,
    REACH_BAND,
    SHOULDER,
    Reference,
    read_objects,
)

from armcli.errors import PlanningError  # noqa: E402
from armcli.plan.api import PlanOptions  # noqa: E402
from armcli.plan.mobile.driving import driving_cost  # noqa: E402
from armcli.plan.mobile.execute import Executed, execute_whole  # noqa: E402
from armcli.plan.mobile.place import place  # noqa: E402
from armcli.plan.mobile.virtual import load_mobile  # noqa: E402
from armcli.plan.mobile.whole import BaseGoal, files, plan_drive, plan_whole  # noqa: E402
from armcli.urdf.source import read_robot  # noqa: E402

SPEC = ROOT / "specs" / "my_robot.yaml"
SCENES = {"empty": None, "office": ROOT / "bench/scenes/office.yaml",
          "warehouse": ROOT / "bench/scenes/warehouse.yaml"}  # fmt: skip
TOLERANCE = 0.01  # [m] placement's default
CELL, YAW_CELL = 0.01, math.radians(1.0)  # the brute-force grid
TURN = 0.225  # [m] half the course robot's wheel separation: the driving cost's turn weight
SEED = 0
REPEATS = 3  # --execute runs per variant: the best is reported


def med(xs: list[float]) -> float:
    return statistics.median(xs) if xs else float("nan")


def targets(n: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Seeded targets over the room, within the arm's heights, and starts near the origin."""
    rng = np.random.default_rng(seed)
    t = np.column_stack([rng.uniform(-2.5, 2.5, n), rng.uniform(-2.5, 2.5, n),
                         rng.uniform(0.05, 0.9, n)])  # fmt: skip
    s = np.column_stack([rng.uniform(-0.5, 0.5, n), rng.uniform(-0.5, 0.5, n),
                         rng.uniform(-math.pi, math.pi, n)])  # fmt: skip
    return list(zip(t, s, strict=True))


def grid(ref: Reference, target: np.ndarray, start: np.ndarray) -> np.ndarray | None:
    """The brute-force grid's least-driving FEASIBLE pose (every cell in reach, judged)."""
    reach = SHOULDER[0] + L1 + L2 + TOLERANCE
    g = np.arange(-math.ceil(reach / CELL), math.ceil(reach / CELL) + 1) * CELL
    cx, cy = np.round(target[0] / CELL) * CELL, np.round(target[1] / CELL) * CELL
    X, Y = (a.ravel() for a in np.meshgrid(cx + g, cy + g, indexing="ij"))
    cells = []
    for deg in range(360):
        yaw = deg * YAW_CELL
        c, s = math.cos(yaw), math.sin(yaw)
        tx = c * (target[0] - X) + s * (target[1] - Y)
        ty = -s * (target[0] - X) + c * (target[1] - Y)
        near = (np.abs(ty) <= TOLERANCE + REACH_BAND) & (tx >= SHOULDER[0] - TOLERANCE - REACH_BAND)
        near &= tx <= reach + REACH_BAND
        cells.append(np.column_stack([X[near], Y[near], np.full(int(near.sum()), yaw)]))
    every = np.concatenate(cells)
    ok = every[ref.classify(every, target) == FEASIBLE]
    if not len(ok):
        return None
    cost = driving_cost(start, ok[:, 0], ok[:, 1], ok[:, 2], TURN)
    return np.asarray(ok[int(np.argmin(cost))])


def bench_place(n: int, g: int) -> None:
    for name, scene in SCENES.items():
        mobile = load_mobile(read_robot(SPEC), scene=scene)
        ref = Reference(read_objects(scene), TOLERANCE)
        cases = targets(n, SEED)
        place(mobile, cases[0][0], cases[0][1])  # warm-up: imports, caches
        times, cpu, placed = [], [], 0
        for t, s in cases:
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                place(mobile, t, s, tolerance=TOLERANCE)
                placed += 1
            except PlanningError:
                pass
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        grid_times = []
        for t, s in cases[:g]:
            t0 = time.perf_counter()
            grid(ref, t, s)
            grid_times.append(time.perf_counter() - t0)
        ratio = med(grid_times) / med(times)
        print(f"place, course robot, {name}: {placed}/{n} placed, median {med(times) * 1e3:.1f} ms"
              f" (p90 {np.percentile(times, 90) * 1e3:.1f} ms; CPU median {med(cpu) * 1e3:.1f} ms);"
              f" brute-force grid on {g}: median "
              f"{med(grid_times):.2f} s; {ratio:.0f}x (targets <= 10 ms, >= 100x)")  # fmt: skip


def bench_plan_base(n: int, g: int) -> None:
    for name, scene in SCENES.items():
        mobile = load_mobile(read_robot(SPEC), scene=scene)
        ref = Reference(read_objects(scene), TOLERANCE)
        times, cpu, grid_times, ok = [], [], [], 0
        for k, (t, s) in enumerate(targets(n, SEED + 1)):
            goal = BaseGoal((float(t[0]), float(t[1]), float(t[2])), (float(s[0]), float(s[1]),
                            float(s[2])))  # fmt: skip
            c0 = time.process_time()
            try:
                d = plan_drive(mobile, goal, SEED)
                times.append(d.planning_time_s)
                cpu.append(time.process_time() - c0)  # with the 3-D certification
                ok += 1
            except PlanningError:
                continue
            if k < g:
                t0 = time.perf_counter()
                grid(ref, t, s)
                grid_times.append(time.perf_counter() - t0)
        print(f"plan --base, course robot, {name}: {ok}/{n} planned, median {med(times) * 1e3:.1f}"
              f" ms (placement + path + timing; target <= 100 ms; CPU median with the 3-D "
              f"certification {med(cpu) * 1e3:.1f} ms); the grid search for the same "
              f"query ({len(grid_times)}): median {med(grid_times):.2f} s")  # fmt: skip


def bench_execute() -> None:
    """The whole execute (drive model, run, judgement) with the compiled steps and without.

    Real time is the peer; MuJoCo's own step on the same model, alone, is the floor.
    """
    import mujoco  # noqa: F401  (imported once per process, not per run: start-up)

    from armcli.drive import step as drivestep
    from armcli.plan.mobile.basefiles import cmd_vel_of

    mobile = load_mobile(read_robot(SPEC), scene=SCENES["warehouse"])
    goal = BaseGoal((1.35, 0.5, 0.42), (-0.5, -1.6, 0.0))  # onto the east rack's low board
    plan = plan_whole(mobile, goal, PlanOptions(seed=SEED))
    out = ROOT / "out" / "bench_place"
    out.mkdir(parents=True, exist_ok=True)
    written = files(plan, out, "bench")
    compiled = drivestep.load()
    for name, module in (("compiled steps", compiled), ("Python steps", None)):
        if name == "compiled steps" and module is None:
            print("--execute: armcli.sim._drivestep not built, compiled steps skipped")
            continue
        drivestep.DRIVESTEP.use(module)
        cpu = wall = math.inf
        for _ in range(REPEATS):  # the first run also pays one-time costs (BLAS discovery)
            c0, w0 = time.process_time(), time.perf_counter()
            done = execute_whole(plan, cmd_vel_of(plan.timing), written[out / "arm.yaml"])
            cpu = min(cpu, time.process_time() - c0)
            wall = min(wall, time.perf_counter() - w0)
        sim = float(done.run.t[-1])
        print(
            f"--execute ({name}), course robot across the warehouse: {sim:.1f} s simulated "
            f"in {cpu:.2f} CPU s / {wall:.2f} s wall, best of {REPEATS}: {sim / cpu:.1f}x real "
            f"time in CPU, {sim / wall:.1f}x wall "
            f"(target >= 50x CPU); tool {done.tool_error * 1e3:.1f} mm from the target"
        )
    drivestep.DRIVESTEP.use(compiled)
    _bare_steps(done)


def _bare_steps(done: Executed) -> None:
    """The floor: MuJoCo's mj_step alone, as many steps on the same model, nothing else."""
    import mujoco

    from armcli.drive.job import start_data

    job = done.run.job
    cpu = math.inf
    for _ in range(REPEATS):
        d = start_data(job.model, job.arm.q0)
        c0 = time.process_time()
        for _ in range(done.run.steps):
            mujoco.mj_step(job.model.model, d)
        cpu = min(cpu, time.process_time() - c0)
    sim = done.run.steps * job.dt
    print(
        f"  (MuJoCo's mj_step alone, the same {done.run.steps} steps standing still: "
        f"{sim / cpu:.1f}x real time in CPU)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--targets", type=int, default=200, help="place targets per room")
    ap.add_argument("--grid", type=int, default=10, help="of which the grid also solves")
    ap.add_argument("--plans", type=int, default=30, help="plan --base targets per room")
    ap.add_argument("--only", choices=("place", "plan", "execute"), help="one section")
    args = ap.parse_args()
    print(
        f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs (times are wall "
        "clock unless CPU is said: on a loaded machine wall time is several times CPU time)"
    )
    if args.only in (None, "place"):
        bench_place(args.targets, args.grid)
    if args.only in (None, "plan"):
        bench_plan_base(args.plans, args.grid)
    if args.only in (None, "execute"):
        bench_execute()
    print(f"load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
