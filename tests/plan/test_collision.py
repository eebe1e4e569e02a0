"""The compiled collision checker against the Python one, and each against an independent check."""

from __future__ import annotations

import numpy as np
import pytest

from armcli.plan.collision import PADDING, CollisionChecker, bisection_order
from armcli.plan.inputs import Loaded
from armcli.plan.native import load
from armcli.plan.srdf import read_srdf
from tests.plan.conftest import PANDA

STATES = 100_000  # issue 36: the two checks agree on 100,000 random states ...
EDGES = 10_000  # ... and 10,000 random edges of the Panda in the bin scene
EDGE_REACH = 1.5  # [rad] edges as the planner grows them: up to this long (Euclidean)
STEP = 0.02  # [rad] edge check step

needs_native = pytest.mark.skipif(load() is None, reason="the compiled planner is not built")


def python_twin(loaded: Loaded) -> CollisionChecker:
    """The same robot, scene and pairs, checked through Pinocchio's Python bindings."""
    disabled = read_srdf(PANDA / "srdf" / "panda.srdf").disabled
    return CollisionChecker(loaded.context.robot, loaded.scene, disabled, native=False)


def edges(robot: object, rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray]:
    lower, upper = robot.lower, robot.upper  # type: ignore[attr-defined]
    a = rng.uniform(lower, upper, (count, len(lower)))
    d = rng.normal(size=a.shape)
    d *= rng.uniform(0.0, EDGE_REACH, (count, 1)) / np.linalg.norm(d, axis=1, keepdims=True)
    return a, np.clip(a + d, lower, upper)


@needs_native
@pytest.mark.slow
def test_compiled_and_python_verdicts_agree(panda_bin: Loaded) -> None:
    compiled, python = panda_bin.context.checker, python_twin(panda_bin)
    robot = panda_bin.context.robot
    rng = np.random.default_rng(36)
    for ck in (compiled, python):
        ck.pad(PADDING, ())  # the planner's check: moving pairs, 5 mm clear
    X = rng.uniform(robot.lower, robot.upper, (STATES, len(robot.joints)))
    assert compiled.native is not None
    fast = compiled.native.free_many(X)
    slow = np.array([python.free(x) for x in X])
    assert np.array_equal(fast, slow), f"{int(np.sum(fast != slow))} states differ"
    assert 0.2 < slow.mean() < 0.95  # both verdicts are common: the test says something
    A, B = edges(robot, rng, EDGES)
    fast = compiled.native.motion_free_many(A, B, STEP)
    slow = np.array([python.motion_free(a, b, STEP) for a, b in zip(A, B, strict=True)])
    assert np.array_equal(fast, slow), f"{int(np.sum(fast != slow))} edges differ"
    assert 0.1 < slow.mean() < 0.9


@needs_native
def test_first_colliding_pair_is_named_alike(panda_bin: Loaded) -> None:
    compiled, python = panda_bin.context.checker, python_twin(panda_bin)
    robot = panda_bin.context.robot
    rng = np.random.default_rng(1)
    hits = 0
    for x in rng.uniform(robot.lower, robot.upper, (400, len(robot.joints))):
        for every in (True, False):
            found = compiled.first_collision(x, every_pair=every)
            assert found == python.first_collision(x, every_pair=every)
            hits += found is not None
    assert hits > 50


@needs_native
def test_padding_spares_the_pairs_already_close_at_the_ends(panda_bin: Loaded) -> None:
    compiled, python = panda_bin.context.checker, python_twin(panda_bin)
    robot = panda_bin.context.robot
    rng = np.random.default_rng(5)
    ends = [x for x in rng.uniform(robot.lower, robot.upper, (200, 7))
            if compiled.first_collision(x) is None][:2]  # fmt: skip
    X = rng.uniform(robot.lower, robot.upper, (3000, 7))
    for ck in (compiled, python):
        ck.pad(0.05, ends)  # 5 cm: pairs closer than that at an end keep no padding there
        assert all(ck.free(x) for x in ends)
    assert compiled.native is not None
    assert np.array_equal(compiled.native.free_many(X), [python.free(x) for x in X])


@needs_native
def test_bisection_order_is_the_python_one() -> None:
    mod = load()
    assert mod is not None
    for n in (1, 2, 3, 7, 50, 64, 333):
        assert mod.bisection_order(n) == bisection_order(n)


def test_bisection_order_checks_every_step_once() -> None:
    for n in (1, 2, 3, 7, 50, 64):
        order = bisection_order(n)
        assert sorted(order) == list(range(1, n + 1))  # each intermediate point exactly once
        assert order[0] == n


@needs_native
def test_compiled_configuration_is_robot_q(panda: Loaded, course: Loaded) -> None:
    # the Panda's finger mimics a joint not planned; the course robot has continuous wheels
    for loaded in (panda, course):
        robot, native = loaded.context.robot, loaded.context.checker.native
        assert native is not None
        rng = np.random.default_rng(0)
        for x in rng.uniform(robot.lower, robot.upper, (20, len(robot.joints))):
            assert np.array_equal(native.q(x), robot.q(x))


@needs_native
def test_lever_bounds_hold(panda_bin: Loaded) -> None:
    # certification's bound (certify.cpp): no point of a geometry moves farther than
    # sum_j lever(g, j) |dx_j| between two configurations; checked on the mesh vertices and
    # box corners moved by Pinocchio's own placements
    import pinocchio as pin

    ck, robot = panda_bin.context.checker, panda_bin.context.robot
    assert ck.native is not None
    lever = ck.native.lever
    data, gdata = robot.model.createData(), pin.GeometryData(ck.gmodel)
    points = [_points(g.geometry) for g in ck.gmodel.geometryObjects]
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(200):
        xa = rng.uniform(robot.lower, robot.upper)
        xb = np.clip(xa + rng.normal(scale=0.3, size=7), robot.lower, robot.upper)
        placed = []
        for x in (xa, xb):
            pin.updateGeometryPlacements(robot.model, data, ck.gmodel, gdata, robot.q(x))
            placed.append([p @ gdata.oMg[g].rotation.T + gdata.oMg[g].translation
                           for g, p in enumerate(points)])  # fmt: skip
        for g in range(len(points)):
            moved = np.max(np.linalg.norm(placed[1][g] - placed[0][g], axis=1))
            bound = lever[g] @ np.abs(xb - xa)
            assert moved <= bound + 1e-12
            worst = max(worst, moved / bound if bound > 0 else 0.0)
    assert worst > 0.1  # and not vacuous: within 10x of the worst true motion (measured 4x)


def _points(geometry: object) -> np.ndarray:
    """A geometry's mesh vertices, or a box's corners, (k, 3) in its own frame."""
    import coal

    if isinstance(geometry, coal.Box):
        h = np.asarray(geometry.halfSide)
        return np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h
    verts = getattr(geometry, "vertices", None)
    if verts is not None:
        return np.asarray(verts())
    return np.zeros((1, 3))


def test_a_pair_close_at_an_end_keeps_half_its_clearance(panda_bin: Loaded) -> None:
    # with no clearance at all such a pair could be planned to touch, and the timed motion's
    # small deviation from the path then made contact (the Panda's link2 and link5 in the
    # bench's open-table scene)
    import pinocchio as pin

    python = python_twin(panda_bin)
    robot = python.robot
    rng = np.random.default_rng(8)
    padding = 0.05
    gdata = pin.GeometryData(python.gmodel)
    for x in rng.uniform(robot.lower, robot.upper, (300, 7)):
        if python.first_collision(x, every_pair=True) is not None:
            continue
        pin.updateGeometryPlacements(robot.model, robot.model.createData(), python.gmodel,
                                     gdata, robot.q(x))  # fmt: skip
        d = [pin.computeDistance(python.gmodel, gdata, k).min_distance if moves else np.inf
             for k, moves in enumerate(python.moving)]  # fmt: skip
        close = [k for k, dk in enumerate(d) if dk < padding]
        if not close:
            continue
        python.pad(padding, [x])
        margins = [req.security_margin for req in python.gdata.collisionRequests]
        for k, moves in enumerate(python.moving):
            if moves:
                expected = 0.5 * d[k] if d[k] < padding else padding  # only closer pairs
                assert margins[k] == pytest.approx(expected, abs=1e-9)
        assert python.free(x)
        return
    pytest.fail("no free state with a pair closer than the padding")  # pragma: no cover


def test_link_pairs_are_the_robots_one_set_up(panda_bin: Loaded) -> None:
    """Plan's self-collision pairs are robot.collision's (check and the matrix use it too).

    The reference: SelfCollision over the robot's own geometry, keeping the pairs the
    Panda's SRDF does not disable; every link then meets every scene object.
    """
    from armcli.robot.collision import SelfCollision

    checker = panda_bin.context.checker
    robot = checker.robot
    disabled = {frozenset(p) for p in read_srdf(PANDA / "srdf" / "panda.srdf").disabled}
    own = SelfCollision(
        robot.robot, lambda a, b: frozenset((a, b)) not in disabled, robot.geometry.copy()
    )
    links = len(robot.geometry.geometryObjects)
    assert [p for p in checker.pairs if p[1] < links] == own.objects
    scene = {(i, j) for i in range(links) for j in range(links, len(checker.bodies))}
    assert {p for p in checker.pairs if p[1] >= links} == scene
    assert len(own.objects) > 10 and len(scene) > 100  # 44 link pairs; 17 shapes x 14 objects
