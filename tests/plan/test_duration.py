"""A plan's motion is bounded in time before it is timed (plan.duration, issue 42).

Before: `limit.acceleration: 1e-9` or `limit.velocity: 1e-6` made `plan` time a motion of
days and sample it at 100 Hz (minutes, 2.7-2.9 GB, a MemoryError). The CLI cases run with
a memory limit, so the code before the fix fails here instead of swapping.
"""

from __future__ import annotations

import math
import resource
from pathlib import Path

import numpy as np
import pytest

from armcli.errors import InputError
from armcli.plan.api import PlanOptions, plan_motion
from armcli.plan.duration import MAX_MOTION_S, check_duration, joint_times
from armcli.plan.inputs import Loaded
from tests.helpers import DEFAULT_SPEC, run_cli
from tests.plan.conftest import TWO_LINK

REL = 1e-12  # closed forms evaluated in floating point
CLI_MEMORY = 4 << 30  # [bytes] the planning process's address space (before: 2.9 GB used)
CLI_TIMEOUT_S = 60.0  # refused in ~2 s; before, it ran for minutes


def test_rest_to_rest_times_match_hand_computed_profiles() -> None:
    # d = 1 rad, v = 1 rad/s, a = 1 rad/s²: accelerate 1 s (0.5 rad), decelerate 1 s -> 2 s.
    # d = 0.25 rad, same limits: v is never reached; 0.5 s up to 0.5 rad/s, 0.5 s down -> 1 s.
    # d = 3 rad: 1 s up (0.5 rad), cruise 2 rad at 1 rad/s (2 s), 1 s down -> 4 s, 2 s of it d/v.
    # d = 2 rad, no velocity limit, a = 2 rad/s²: 2·sqrt(d/a) = 2 s.
    t, tv = joint_times(
        np.array([1.0, -0.25, 3.0, 2.0]),
        np.array([1.0, 1.0, 1.0, math.inf]),
        np.array([1.0, 1.0, 1.0, 2.0]),
    )
    assert t == pytest.approx([2.0, 1.0, 4.0, 2.0], rel=REL)
    assert tv == pytest.approx([1.0, 0.0, 3.0, 0.0], rel=REL)


def test_the_bound_never_exceeds_the_timed_motion(two_link: Loaded) -> None:
    """A lower bound: TOPP-RA's motion along the same path is never shorter."""
    ctx = two_link.context
    res = plan_motion(ctx, [-1.4, 0.5], [1.4, -0.5], PlanOptions(seed=3))
    robot = ctx.robot
    bound = sum(
        float(np.max(joint_times(d, robot.velocity, robot.acceleration)[0]))
        for d in np.diff(res.path, axis=0)
    )
    assert 0.0 < bound <= res.duration_s


def test_a_timed_motion_over_the_bound_is_not_sampled() -> None:
    check_duration(MAX_MOTION_S)
    for duration in (MAX_MOTION_S * 1.01, math.nan, math.inf):
        with pytest.raises(InputError, match="not sampled"):
            check_duration(duration)


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (CLI_MEMORY, CLI_MEMORY))


ACC = "limit.acceleration 1e-09 rad/s²"
VEL = "limit.velocity 1e-06 rad/s"
ARM = "joint arm_base_forearm_joint"


@pytest.mark.parametrize(
    ("kind", "edit", "expected"),
    [
        ("urdf", ('acceleration="6"', 'acceleration="1e-9"'), f"joint shoulder: {ACC}"),
        ("urdf", ('velocity="1.5" acceleration="6"', 'velocity="1e-6" acceleration="6"'),
         f"joint shoulder: {VEL}"),
        ("spec", ("velocity: 100}", "velocity: 1e-6}"), f"{ARM}: {VEL}"),
        ("spec", ("velocity: 100}", "velocity: 100, acceleration: 1e-9}"), f"{ARM}: {ACC}"),
    ],
)  # fmt: skip
def test_tiny_limits_are_refused_in_one_line(
    kind: str, edit: tuple[str, str], expected: str, tmp_path: Path
) -> None:
    src = TWO_LINK if kind == "urdf" else DEFAULT_SPEC
    robot = tmp_path / src.name
    robot.write_text(src.read_text().replace(*edit))
    out = tmp_path / "plan.yaml"
    args: list[str | Path] = ["--urdf", robot, "--from", "0,0", "--to", "1,1"]
    if kind == "spec":
        args = [robot, "--to", "reach"]
    proc = run_cli(["plan", *args, "-o", out], tmp_path, preexec_fn=_limited, timeout=CLI_TIMEOUT_S)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith(f"error: {robot}: {expected} makes this motion last at least")
    assert f"more than the {MAX_MOTION_S:g} s a plan may take" in proc.stderr
    assert len(proc.stderr.splitlines()) == 1 and not out.exists()
