"""Benchmark: `armcli plan` against roboplan 0.7.0 and a plain OMPL + Python validity check.

Run with `make bench` (or `python bench/bench_plan.py [--queries N] [--ik N] [--process N]`).

1. The course arm (specs/my_robot.yaml) around a box (tests/fixtures/plan/box_in_the_way.yaml):
   home <-> each other named pose, median path time (planning + shortcutting; target
   <= 5 ms) and plan + parameterisation.
2. IK on the Panda: N random reachable poses (position and orientation), success, median.
3. The Panda (example-robot-data, its SRDF) in four scene kinds (bench/plan_peers.py: open
   table, shelf, cluttered bin, slot in a wall), N seeded queries each, the same for every
   planner, 1 s limit: armcli (plan_motion: compiled RRT-Connect + shortcutting, TOPP-RA,
   certification), roboplan (C++ RRT-Connect + its PathShortcutter), the floor (OMPL
   RRT-Connect, Python callback). Per kind: solved, median and p90 path time (planning +
   simplification, the figure roboplan reports), armcli/roboplan median ratio (target <=
   0.5; also over the queries both solved: each median is over its own solved set, and the
   one solving more hard queries pays for them), path length armcli/roboplan over the
   queries both solved, certification time (wall and CPU),
   how many armcli paths are one straight segment, and the independent 1 kHz check
   (tests/plan/oracle.py) of every armcli trajectory.
4. Whole process: `armcli plan` as a user runs it (model, SRDF, scene, plan, timing,
   certification, writing) beside the same query in roboplan's Python API
   (bench/roboplan_query.py), CPU time of each process (target <= 1 s median).
Not a test: numbers depend on the machine and its load (printed first).
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from plan_peers import (  # noqa: E402
    ERD,
    KINDS,
    PANDA,
    PANDA_ARM,
    SCENES,
    STEP,
    TIMEOUT_S,
    UR5_ARM,
    Arm,
    Kind,
    Roboplan,
    floor_plan,
    panda_context,
    queries,
)
from tests.plan.oracle import Oracle  # noqa: E402

from armcli.defaults import DEFAULT_JOINT_ACCELERATION  # noqa: E402
from armcli.errors import PlanningError  # noqa: E402
from armcli.plan.api import PlanOptions, plan_motion  # noqa: E402
from armcli.plan.ik import solve_ik, tool_pose  # noqa: E402
from armcli.plan.inputs import load_context  # noqa: E402
from armcli.urdf.source import read_robot  # noqa: E402

SPEC = ROOT / "specs" / "my_robot.yaml"
BOX = ROOT / "tests" / "fixtures" / "plan" / "box_in_the_way.yaml"
SEED = 0
COURSE_REPEATS = 30
FREE_PROBES = 200  # random states tried before drawing another arm's queries


def med(xs: list[float]) -> float:
    return statistics.median(xs) if xs else float("nan")


def p90(xs: list[float]) -> float:
    return float(np.percentile(xs, 90)) if xs else float("nan")


def length(path: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))


def course() -> None:
    ctx = load_context(read_robot(SPEC), scene=BOX).context
    r = ctx.robot
    others = [p for p in sorted(r.poses) if p != "home"]
    paths, plans = [], []
    plan_motion(ctx, r.pose("home"), r.pose(others[0]), PlanOptions())  # warm-up
    for k in range(COURSE_REPEATS):
        for other in others:
            for a, b in (("home", other), (other, "home")):
                res = plan_motion(ctx, r.pose(a), r.pose(b), PlanOptions(seed=k))
                paths.append(res.path_time_s)
                plans.append(res.planning_time_s)
    print(f"course arm around a box, home <-> {', '.join(others)}, {len(paths)} plans: median "
          f"path time {med(paths) * 1e3:.2f} ms (target <= 5 ms), with parameterisation "
          f"{med(plans) * 1e3:.2f} ms")  # fmt: skip


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
        f"median {med(times) * 1e3:.2f} ms"
    )


def oracle_for(scene: Path, arm: Arm = PANDA_ARM) -> Oracle:
    """The independent checker of tests/plan/oracle.py on the arm in `scene`."""
    acc = {j: DEFAULT_JOINT_ACCELERATION for j in arm.joints}  # their URDFs give none
    return Oracle(arm.urdf, arm.srdf, [str(ERD.parent)], scene, acc)


HEAD = (f"{'kind':15} {'planner':9} {'solved':>7} {'median':>8} {'p90':>8} (CPU median / p90)  "
        "ratio to roboplan, path length ratio, certification, motion, 1 kHz check")  # fmt: skip


def panda(count: int, seed: int) -> dict[str, list[tuple[np.ndarray, np.ndarray]]]:
    print(f"Panda, {count} queries per scene kind (seed {seed}), {TIMEOUT_S:g} s limit; times "
          "are planning + simplification [ms], median / p90 over the solved queries")  # fmt: skip
    print(HEAD)
    return {kind.scene: compare(kind, PANDA_ARM, count, seed) for kind in KINDS}


def other_arm(count: int, seed: int) -> None:
    print(f"UR5 (example-robot-data, its SRDF; not tuned for) at the open table, {count} "
          f"queries (seed {seed})")  # fmt: skip
    kind = KINDS[0]  # its tool rarely reaches into the bin or beyond the wall at random
    ck = panda_context(SCENES / kind.scene, UR5_ARM).context.checker
    rng = np.random.default_rng(seed)
    lo, hi = ck.robot.lower, ck.robot.upper
    hits = [ck.first_collision(rng.uniform(lo, hi), every_pair=True) for _ in range(FREE_PROBES)]
    if all(hits):  # no query can be drawn: say why instead of searching forever
        print(f"  none of {FREE_PROBES} random states is free (first: {hits[0]}): its SRDF "
              "leaves these link pairs enabled")  # fmt: skip
        return
    print(HEAD)
    compare(kind, UR5_ARM, count, seed, floor=False)


def compare(kind: Kind, arm: Arm, count: int, seed: int, floor: bool = True
            ) -> list[tuple[np.ndarray, np.ndarray]]:  # fmt: skip
    """armcli, roboplan and the floor on `count` queries of `kind`; prints one line each."""
    loaded = panda_context(SCENES / kind.scene, arm)
    ctx = loaded.context
    rb = Roboplan(loaded.scene, arm)
    qs = queries(kind, ctx, rb, count, seed)
    oracle = oracle_for(SCENES / kind.scene, arm)
    t: dict[str, list[float]] = {"armcli": [], "roboplan": [], "floor": []}
    cpu: dict[str, list[float]] = {"armcli": [], "roboplan": []}  # path time, CPU
    ratios, cert, cert_cpu, motion, straight, bad, checked = [], [], [], [], 0, 0, 0
    both: list[tuple[float, float]] = []  # (armcli, roboplan) on the queries both solved
    for k, (a, b) in enumerate(qs):
        mine = None
        try:
            res = plan_motion(ctx, a, b, PlanOptions(seed=k, timeout=TIMEOUT_S, step=STEP))
            if res.path_time_s <= TIMEOUT_S:
                t["armcli"].append(res.path_time_s)
                cpu["armcli"].append(res.path_cpu_s)
                cert.append(res.certify_time_s)
                cert_cpu.append(res.certify_cpu_s)
                motion.append(res.duration_s)
                mine, straight = res.path, straight + (len(res.path) == 2)
                report = oracle.check(res.document)
                checked += report.samples
                bad += not report.ok
                if not report.ok:
                    print(f"  query {k}: the independent check fails: {report.first}")
        except PlanningError as exc:
            print(f"  query {k}: armcli: {exc.kind}: {exc.reason}")
        c0 = time.process_time()
        dt, path = rb.plan(a, b, k)
        if path is not None and dt <= TIMEOUT_S:
            t["roboplan"].append(dt)
            cpu["roboplan"].append(time.process_time() - c0)
            if mine is not None:
                ratios.append(length(mine) / length(path))
                both.append((t["armcli"][-1], dt))
        if floor:
            dt, path = floor_plan(ctx, a, b, k)
            if path is not None and dt <= TIMEOUT_S:
                t["floor"].append(dt)
    ratio = med(t["armcli"]) / med(t["roboplan"])
    paired = med([a for a, _ in both]) / med([b for _, b in both])
    for who in ("armcli", "roboplan", "floor") if floor else ("armcli", "roboplan"):
        xs = t[who]
        line = f"{kind.name:15} {who:9} {len(xs):>3}/{count:<3} {med(xs) * 1e3:8.1f} "
        line += f"{p90(xs) * 1e3:8.1f}"
        if who in cpu:
            line += f" (CPU {med(cpu[who]) * 1e3:.1f} / {p90(cpu[who]) * 1e3:.1f})"
        if who == "armcli":
            line += (f"  {ratio:.2f} ({paired:.2f} on the {len(both)} both solved), "
                     f"{med(ratios):.2f}, "
                     f"{med(cert) * 1e3:.0f} ms median ({p90(cert) * 1e3:.0f} p90; CPU "
                     f"{med(cert_cpu) * 1e3:.0f} ms), motion {med(motion):.1f} s median, "
                     f"{bad} of {len(xs)} fail ({checked} samples); "
                     f"straight: {straight}")  # fmt: skip
        print(line, flush=True)
    return qs


def cpu_of(cmd: list[str]) -> tuple[float, int]:
    """(CPU seconds of the child process, its exit code)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    rc = subprocess.run(cmd, capture_output=True, check=False).returncode
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), rc


def process(chosen: dict[str, list[tuple[np.ndarray, np.ndarray]]], count: int) -> None:
    armcli = Path(sys.executable).parent / "armcli"
    ours, theirs, failed = [], [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for scene, qs in chosen.items():
            for k, (a, b) in enumerate(qs[:count]):
                start, goal = (",".join(repr(float(v)) for v in x) for x in (a, b))
                out = os.path.join(tmp, f"{k}.yaml")
                cpu, rc = cpu_of([str(armcli), "plan", "--urdf", str(PANDA / "urdf" / "panda.urdf"),
                                  "--srdf", str(PANDA / "srdf" / "panda.srdf"), "--group", "arm",
                                  "--scene", str(SCENES / scene), "--from", start, "--to", goal,
                                  "--seed", str(k), "--package-dir",
                                  f"example-robot-data={ERD}", "-o", out])  # fmt: skip
                if rc == 0:
                    ours.append(cpu)
                failed += rc != 0
                cpu, rc = cpu_of([sys.executable, str(ROOT / "bench" / "roboplan_query.py"),
                                  str(SCENES / scene), start, goal, out + ".rp"])  # fmt: skip
                if rc == 0:
                    theirs.append(cpu)
    print(f"whole process, CPU per query ({len(ours)} armcli plan, {failed} failed; "
          f"{len(theirs)} roboplan): armcli median {med(ours):.2f} s (p90 {p90(ours):.2f}; "
          f"target <= 1 s), roboplan's Python API median {med(theirs):.2f} s "
          f"(p90 {p90(theirs):.2f})")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--queries", type=int, default=30, help="start/goal pairs per scene kind")
    ap.add_argument("--ik", type=int, default=300, help="IK poses")
    ap.add_argument("--process", type=int, default=5, help="whole-process runs per scene kind")
    ap.add_argument("--other", type=int, default=20, help="UR5 queries per scene kind")
    ap.add_argument("--seed", type=int, default=SEED,
                    help="query seed (0: the benchmark's; others: held-out sets)")  # fmt: skip
    args = ap.parse_args()
    print(f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f} "
          f"on {os.cpu_count()} CPUs")  # fmt: skip
    course()
    if not PANDA.is_dir():
        print("Panda: example-robot-data not installed, skipped")
        return
    ik(args.ik)
    chosen = panda(args.queries, args.seed)
    process(chosen, args.process)
    other_arm(args.other, args.seed)


if __name__ == "__main__":
    main()
