"""plan_motion end to end: paths vs an independent collision check, timing vs every limit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.errors import PlanningError
from armcli.plan.api import PlanOptions, plan_motion
from armcli.plan.certify import sample
from armcli.plan.inputs import Loaded
from armcli.plan.timing import inverse_dynamics
from tests.plan.test_ik import LINK, SHOULDER

# tests/fixtures/plan/box_in_the_way.yaml: the box, centre and half sizes [m] in base_footprint
BOX_CENTRE, BOX_HALF = np.array([0.45, 0.0, 0.85]), np.array([0.02, 0.1, 0.02])
RADIUS = 0.02  # [m] forearm and hand cylinders (specs/my_robot.yaml)
FD_RATE = 10_000.0  # [Hz] finite differences of the interpolated positions
FD_TOL = 0.01  # relative: finite-difference error at 10 kHz on these motions is far below 1 %


def cylinder_points(base: np.ndarray, q: float) -> np.ndarray:
    """Points filling a link cylinder from `base` along (sin q, 0, cos q), 0.3 m long."""
    u = np.array([math.sin(q), 0.0, math.cos(q)])
    x, y = np.array([math.cos(q), 0.0, -math.sin(q)]), np.array([0.0, 1.0, 0.0])
    t = np.linspace(0.0, LINK, 61)[:, None, None, None]
    r = np.array([0.0, RADIUS / 2, RADIUS])[None, :, None, None]
    phi = np.linspace(0.0, 2 * math.pi, 16, endpoint=False)[None, None, :, None]
    pts = base + t * u + r * (np.cos(phi) * x + np.sin(phi) * y)
    return pts.reshape(-1, 3)


def arm_hits_box(q1: float, q2: float) -> bool:
    """Independent check (closed-form kinematics, sampled volumes): an arm point in the box."""
    elbow = SHOULDER + LINK * np.array([math.sin(q1), 0.0, math.cos(q1)])
    pts = np.vstack([cylinder_points(SHOULDER, q1), cylinder_points(elbow, q1 + q2)])
    return bool(np.any(np.all(np.abs(pts - BOX_CENTRE) <= BOX_HALF, axis=1)))


def test_plan_around_the_box_is_collision_free(course_box: Loaded) -> None:
    ctx = course_box.context
    home, reach = ctx.robot.pose("home"), ctx.robot.pose("reach")
    # the straight motion would hit the box (the independent check says so too)
    assert any(arm_hits_box(*(home + (reach - home) * u)) for u in np.linspace(0, 1, 201))
    for seed in range(3):
        result = plan_motion(ctx, home, reach, PlanOptions(seed=seed))
        assert len(result.path) > 2  # it went around
        s = sample(ctx.robot, result.timed)  # 1 kHz through simulate's interpolation
        hits = [t for t, q in zip(s.t, s.q, strict=True) if arm_hits_box(*q)]
        assert not hits, f"seed {seed}: the arm is in the box at t = {hits[0]:.3f} s"


def test_trajectory_within_every_limit(two_link: Loaded) -> None:
    ctx = two_link.context
    robot = ctx.robot
    result = plan_motion(ctx, [-1.2, 0.0], [1.2, 0.0], PlanOptions())
    s = sample(robot, result.timed, FD_RATE)
    dt = 1.0 / FD_RATE
    v = np.gradient(s.q, dt, axis=0)  # finite differences, not the polynomial's derivatives
    a = np.gradient(v, dt, axis=0)
    tau_of = inverse_dynamics(robot)
    tau = np.array([tau_of(q, qd, qdd) for q, qd, qdd in zip(s.q, v, a, strict=True)])
    assert np.all(s.q >= robot.lower - 1e-6) and np.all(s.q <= robot.upper + 1e-6)
    assert np.all(np.abs(v) <= robot.velocity * (1 + FD_TOL))
    assert np.all(np.abs(a[2:-2]) <= robot.acceleration * (1 + FD_TOL))
    assert np.all(np.abs(tau[2:-2]) <= robot.effort * (1 + FD_TOL))
    # The effort limit binds: holding the straight arm at 1.2 rad takes g sin(1.2) (1 kg at
    # 0.2 m + 1 kg at 0.6 m) = 7.31 N·m, and starting at the shoulder's acceleration limit
    # 6 rad/s² with inertia 0.0134 + 0.2² + 0.0134 + 0.6² = 0.427 kg·m² would need 9.87 N·m,
    # beyond the 9 N·m limit: the planner must start slower than the acceleration limit.
    needed = 9.81 * math.sin(1.2) * (0.2 + 0.6) + 0.427 * 6.0
    assert needed > robot.effort[0]
    assert abs(a[2, 0]) < 0.9 * robot.acceleration[0]


def test_same_seed_same_bytes(course_box: Loaded) -> None:
    ctx = course_box.context
    home, reach = ctx.robot.pose("home"), ctx.robot.pose("reach")
    first = plan_motion(ctx, home, reach, PlanOptions(seed=4)).document
    assert plan_motion(ctx, home, reach, PlanOptions(seed=4)).document == first


def test_goal_in_the_box_names_link_and_object(course_box: Loaded) -> None:
    ctx = course_box.context
    goal = next(
        np.array([a, b])
        for a in np.linspace(0.0, 1.5, 31)
        for b in np.linspace(0.0, 1.5, 31)
        if arm_hits_box(a, b)
    )
    with pytest.raises(PlanningError) as info:
        plan_motion(ctx, ctx.robot.pose("home"), goal, PlanOptions())
    assert info.value.kind == "goal-collision"
    assert set(info.value.pair or ()) == {"hand_link", "box"}


def test_goal_outside_the_limits(course: Loaded) -> None:
    with pytest.raises(PlanningError, match="forearm_hand_joint = 2") as info:
        plan_motion(course.context, [0.0, 0.0], [0.5, 2.0], PlanOptions())
    assert info.value.kind == "goal-limits"


def test_fast_configuration_matches_the_joint_by_joint_one(panda: Loaded, course: Loaded) -> None:
    # the Panda's finger joint 2 mimics joint 1 (locked); the course arm has continuous wheels
    for loaded in (panda, course):
        robot = loaded.context.robot
        rng = np.random.default_rng(0)
        for _ in range(5):
            x = rng.uniform(robot.lower, robot.upper)
            assert np.array_equal(robot.q(x), robot.q_slow(x))


def test_bisection_order_checks_every_step_once() -> None:
    from armcli.plan.collision import bisection_order

    for n in (1, 2, 3, 7, 50, 64):
        order = bisection_order(n)
        assert sorted(order) == list(range(1, n + 1))  # each intermediate point exactly once
        assert order[0] == n
