"""TOPP-RA through the compiled planner (libtoppra) against TOPP-RA's Python package."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from armcli.errors import PlanningError
from armcli.plan.inputs import Loaded
from armcli.plan.native import load
from armcli.plan.timing import Timed, parameterise

# The two implement the same algorithm (reachability analysis, Seidel's LP solver, the same
# grid and constraints); they differ in floating-point order only. Measured worst cases on
# random Panda paths: duration 5e-7 relative, positions 1.3e-6 rad, accelerations 1.2e-4
# rad/s² (the spline amplifies position differences by 1 / dt² at 100 Hz).
DURATION_TOL = 1e-5  # relative
POSITION_TOL = 1e-5  # [rad]
VELOCITY_TOL = 1e-4  # [rad/s]
ACCELERATION_TOL = 5e-3  # [rad/s²]

needs_native = pytest.mark.skipif(load() is None, reason="the compiled planner is not built")


def timed(robot: Any, W: np.ndarray, margin: float, native: Any = None) -> Timed | str:
    """The timing, or the reason there is none."""
    try:
        return parameterise(robot, W, margin, native)
    except PlanningError as exc:
        return exc.reason


@needs_native
def test_compiled_timing_is_the_python_packages(panda: Loaded, two_link: Loaded) -> None:
    # the Panda (effort limits: torque constraint on), the two-link arm (effort binding)
    rng = np.random.default_rng(7)
    for loaded in (panda, two_link):
        robot, native = loaded.context.robot, loaded.context.checker.native
        for _ in range(6):
            W = rng.uniform(robot.lower, robot.upper, (int(rng.integers(2, 5)), len(robot.joints)))
            for margin in (0.78, 0.45):
                ref, got = timed(robot, W, margin), timed(robot, W, margin, native)
                if isinstance(ref, str) or isinstance(got, str):  # gravity beyond the effort
                    assert ref == got  # limit: both find no motion, on the same segment
                    continue
                assert got.duration == pytest.approx(ref.duration, rel=DURATION_TOL)
                assert got.times.shape == ref.times.shape
                assert np.max(np.abs(got.positions - ref.positions)) < POSITION_TOL
                assert np.max(np.abs(got.velocities - ref.velocities)) < VELOCITY_TOL
                assert np.max(np.abs(got.accelerations - ref.accelerations)) < ACCELERATION_TOL


@needs_native
def test_spline_is_scipys_clamped_cubic() -> None:
    from scipy.interpolate import CubicSpline

    mod = load()
    assert mod is not None
    rng = np.random.default_rng(2)
    for points in (2, 3, 4, 17, 200):
        t = np.linspace(0.0, rng.uniform(0.1, 5.0), points)
        y = rng.normal(size=(points, 3))
        v, a = mod.spline(t, y)
        cs = CubicSpline(t, y, bc_type=((1, np.zeros(3)), (1, np.zeros(3))))
        scale = np.max(np.abs(cs(t, 2))) + 1.0
        assert np.allclose(v, cs(t, 1), rtol=0, atol=1e-9 * scale)
        assert np.allclose(a, cs(t, 2), rtol=0, atol=1e-9 * scale)


@needs_native
def test_blended_corners_stay_free_and_shorten_the_motion(panda_bin: Loaded) -> None:
    # planned paths with corners in the bin: rounded corners (plan.timing's blend) must keep
    # every output sample inside the limits and free by the exact Python check (plan.collision
    # without the extension), and the motion, no longer stopping at corners, is shorter
    from armcli.plan.collision import PADDING
    from armcli.plan.geometric import plan_path
    from tests.plan.test_collision import python_twin
    from tests.plan.test_geometric import blocked_pairs

    robot, checker = panda_bin.context.robot, panda_bin.context.checker
    python = python_twin(panda_bin)
    faster = 0
    for k, (a, b) in enumerate(blocked_pairs(panda_bin, 4, 9)):
        checker.pad(PADDING, (a, b))
        path = plan_path(checker, robot.lower, robot.upper, a, b, seed=k, timeout=30.0)
        if len(path) < 3:
            continue
        stops = parameterise(robot, path, 0.6, checker.native)
        blended = parameterise(robot, path, 0.6, checker.native, blend=0.45)
        assert np.array_equal(blended.positions[[0, -1]], path[[0, -1]])
        assert np.all(blended.positions >= robot.lower) and np.all(blended.positions <= robot.upper)
        assert all(python.first_collision(x, every_pair=True) is None for x in blended.positions)
        faster += blended.duration < stops.duration
    assert faster >= 2
