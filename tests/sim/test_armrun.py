"""One fixed-base run with its balance: `simulate`, `check -t` and `plan --execute` share it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from armcli.sim.armrun import ArmRun, run_balanced, simulate_arm, trajectory_zmp
from armcli.sim.options import SimOptions
from armcli.sim.tipping import TipOptions, whole_robot
from armcli.urdf.source import RobotFile
from tests.helpers import DEFAULT_SPEC, ROOT, spec_file

PICK = ROOT / "src" / "armcli" / "examples" / "trajectories" / "pick.yaml"


@pytest.fixture(scope="module")
def course_run() -> tuple[RobotFile, ArmRun]:
    file = spec_file(DEFAULT_SPEC)
    return file, simulate_arm(file, SimOptions(trajectory=PICK), TipOptions(payload=0.2))


def test_simulate_and_check_report_the_same_zero_moment_point(
    course_run: tuple[RobotFile, ArmRun],
) -> None:
    file, run = course_run
    assert run.tip is not None and run.balance is not None and run.series is not None
    whole = whole_robot(file)
    r = trajectory_zmp(file, whole, run.tip.stance, PICK, run.tip.base_accel, run.tip.threshold)
    # the same run, the same numbers field by field; only the label of the given accel differs
    assert replace(r, accel_source=run.balance.accel_source) == run.balance


def test_the_kept_steps_change_what_is_recorded_not_the_motion(
    course_run: tuple[RobotFile, ArmRun],
) -> None:
    _, run = course_run
    dense = run_balanced(run.job, run.tip, every_step=True)
    sparse = run_balanced(run.job, None)  # no balance: the output rate's states only
    assert dense.balance == run.balance and sparse.balance is None
    steps = dense.result.steps
    assert len(dense.result.t) == steps + 1 > len(sparse.result.t)
    at = np.searchsorted(dense.result.step, sparse.result.step)  # the same states, bit for bit
    np.testing.assert_array_equal(dense.result.q[at], sparse.result.q)


def test_the_states_file_carries_the_balance_columns(
    course_run: tuple[RobotFile, ArmRun], tmp_path: Path
) -> None:
    _, run = course_run
    out = tmp_path / "run.csv"
    header = run.files(out, None)[out].decode().splitlines()[0].split(",")
    assert {"zmp.x", "zmp.y", "zmp.margin", "zmp.margin_base"} <= set(header)
    assert run.files(None, None) == {}
