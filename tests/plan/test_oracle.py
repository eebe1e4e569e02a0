"""Plans in the benchmark's scene kinds pass the independent 1 kHz check (tests/plan/oracle.py)."""

from __future__ import annotations

import numpy as np
import pytest

from armcli.defaults import DEFAULT_JOINT_ACCELERATION
from armcli.plan.api import PlanOptions, plan_motion
from armcli.plan.output import trajectory_yaml
from armcli.plan.timing import Timed
from tests.plan.conftest import BENCH_SCENES, ERD, PANDA, panda_in
from tests.plan.oracle import Oracle

ARM = [f"panda_joint{i}" for i in range(1, 8)]
KINDS = ("panda_open_table.yaml", "panda_cabinet.yaml", "panda_bin.yaml", "panda_slot.yaml")
QUERIES = 2  # per scene kind (bench/bench_plan.py checks every benchmark plan)


def oracle(scene: str) -> Oracle:
    acc = {j: DEFAULT_JOINT_ACCELERATION for j in ARM}  # the Panda's URDF has none
    return Oracle(PANDA / "urdf" / "panda.urdf", PANDA / "srdf" / "panda.srdf",
                  [str(ERD.parent)], BENCH_SCENES / scene, acc)  # fmt: skip


def free_states(loaded, rng: np.random.Generator, count: int) -> list[np.ndarray]:
    ck, robot = loaded.context.checker, loaded.context.robot
    out: list[np.ndarray] = []
    while len(out) < count:
        x = rng.uniform(robot.lower, robot.upper)
        if ck.first_collision(x, every_pair=True) is None:
            out.append(x)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("scene", KINDS)
def test_plans_pass_the_independent_check(scene: str) -> None:
    loaded = panda_in(BENCH_SCENES / scene)
    check = oracle(scene)
    rng = np.random.default_rng(11)
    ends = free_states(loaded, rng, 2 * QUERIES)
    for k in range(QUERIES):
        result = plan_motion(loaded.context, ends[2 * k], ends[2 * k + 1],
                             PlanOptions(seed=k, timeout=5.0))  # fmt: skip
        report = check.check(result.document)
        assert report.ok, report.first
        assert report.samples >= result.duration_s * 1000


def test_the_check_finds_a_collision_and_a_limit() -> None:
    # not a checker that passes everything: straight through the bin's wall, and too fast
    loaded = panda_in(BENCH_SCENES / "panda_bin.yaml")
    robot = loaded.context.robot
    check = oracle("panda_bin.yaml")
    a = np.array([0.0, 0.3, 0.0, -1.5, 0.0, 1.8, 0.8])
    b = np.array([0.0, 1.3, 0.0, -1.2, 0.0, 2.5, 0.8])  # the hand down into the bin's wall
    t = np.linspace(0.0, 4.0, 41)
    u = (t / t[-1])[:, None]
    q = a + (b - a) * (3 * u**2 - 2 * u**3)  # slow enough for every limit
    qd = (b - a) * (6 * u - 6 * u**2) / t[-1]
    qdd = (b - a) * (6 - 12 * u) / t[-1] ** 2
    doc = trajectory_yaml(robot.joints, Timed(t, q, qd, qdd), frame_id="")
    report = check.check(doc)
    assert report.violations["collision"] > 0, report
    assert loaded.context.checker.first_collision(b) is not None  # armcli agrees it collides
    fast = trajectory_yaml(robot.joints, Timed(t / 20, q, qd * 20, qdd * 400), frame_id="")
    report = check.check(fast)
    assert report.violations["velocity"] > 0 and report.violations["acceleration"] > 0
