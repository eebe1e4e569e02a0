"""Loading the compiled planner: its source hash, the ARMCLI_NO_NATIVE switch, the fallback."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from armcli.plan import native
from armcli.plan.inputs import Loaded


def run(code: str, **env: str) -> subprocess.CompletedProcess[str]:
    import os

    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={**os.environ, **env}, check=False)  # fmt: skip


def test_built_from_these_sources() -> None:
    mod = native.load()
    if mod is None:
        pytest.skip(f"the compiled planner is not built: {native.why_missing()}")
    assert native.source_hash() == mod.SOURCE_SHA256


def test_no_native_switch_gives_the_python_path() -> None:
    r = run("from armcli.plan import native; print(native.load(), native.why_missing())",
            ARMCLI_NO_NATIVE="1")  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert r.stdout.split()[0] == "None" and "ARMCLI_NO_NATIVE" in r.stdout


def test_the_python_path_plans_too(course_box: Loaded) -> None:
    # without the extension: OMPL with the Python checker, TOPP-RA's Python package
    from armcli.plan.api import PlanningContext, PlanOptions, plan_motion
    from armcli.plan.collision import CollisionChecker
    from armcli.plan.srdf import allowed_pairs

    ctx = course_box.context
    disabled = allowed_pairs(course_box.robot_file, None)
    python = PlanningContext(
        ctx.robot, CollisionChecker(ctx.robot, course_box.scene, disabled, native=False)
    )
    assert python.checker.native is None
    home, reach = ctx.robot.pose("home"), ctx.robot.pose("reach")
    result = plan_motion(python, home, reach, PlanOptions(seed=1))
    assert len(result.path) > 2 and np.array_equal(result.path[0], home)
