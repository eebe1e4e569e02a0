"""`plan --base --execute` on the MuJoCo drive: three scenes, a target on a table in each.

Obstacles on the floor and a low table carrying the target (tests/fixtures/plan/mobile/):
the cluttered room (from off the origin, turned), a corridor, a partition to drive around.
Judged on MuJoCo's ground truth (the root body's pose, the arm's joint positions through
the model's kinematics): the tool within EXECUTE_TOL of the target, no limit broken, no tip;
the encoder odometry the follower integrates agrees with the plugin's (drive.diffdrive, from
the recorded wheel speeds) to ODOMETRY_TOL (they differ by which step's speed a step uses).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.plan.api import PlanOptions
from armcli.plan.mobile.execute import execute_whole, run_files
from armcli.plan.mobile.virtual import load_mobile
from armcli.plan.mobile.whole import BaseGoal, files, plan_whole
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC, FIXTURES

MOBILE = FIXTURES / "plan" / "mobile"
EXECUTE_TOL = 0.02  # [m] the bound on the tool's final distance (ground truth)
ODOMETRY_TOL = 1e-3  # [m, rad] the follower's odometry against the plugin's
# scene, target on its table (the files' numbers: 3-7 cm above the table top), base start
CASES = {
    "cluttered": (MOBILE / "cluttered_room.yaml", (1.35, 0.0, 0.5), (-0.5, -0.5, 1.0)),
    "corridor": (MOBILE / "corridor.yaml", (3.0, 0.0, 0.47), (0.0, 0.0, 0.0)),
    "detour": (MOBILE / "detour.yaml", (1.95, -0.2, 0.48), (0.0, 0.0, 0.0)),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_whole_plan_executes_on_the_drive(name: str, tmp_path: Path) -> None:
    scene, target, start = CASES[name]
    mobile = load_mobile(read_robot(DEFAULT_SPEC), scene=scene)
    plan = plan_whole(mobile, BaseGoal(target, start), PlanOptions(seed=0))
    written = files(plan, tmp_path, name)
    for path, data in written.items():
        path.write_bytes(data)
    done = execute_whole(plan, tmp_path / "cmd_vel.yaml", written[tmp_path / "arm.yaml"])
    assert done.tool_error <= EXECUTE_TOL, done.problems
    assert not done.problems, done.problems
    assert not done.verdict.tips
    assert done.arrived is not None
    odom = done.run.odometry  # the plugin's, from the recorded wheel speeds
    assert np.allclose(done.odometry, (odom.x[-1], odom.y[-1], odom.yaw[-1]), atol=ODOMETRY_TOL)
    outputs = run_files(plan, done, tmp_path)
    assert set(p.name for p in outputs) == {"run.csv", "run.mcap"}
