"""Base placement of the course robot against the brute-force reference grid.

The reference (tests/plan/mobile/reference.py) judges base poses on a grid of 1 cm and
1 degree with its own closed-form kinematics, shapes and collision tests. On seeded random
targets in an empty room and in a cluttered one: no placed pose is infeasible for the
reference, every target the reference grid can reach is placed, and the reported region
matches the grid's feasible cells along each axis through the pose to within one cell.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.plan.mobile.place import PlacementError, place
from armcli.plan.mobile.virtual import MobileRobot, load_mobile
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC, FIXTURES
from tests.plan.mobile.reference import (
    AMBIGUOUS,
    FEASIBLE,
    INFEASIBLE,
    L1,
    L2,
    REACH_BAND,
    SHOULDER,
    Box,
    Cylinder,
    Reference,
    arm_points,
    read_objects,
)

CLUTTERED = FIXTURES / "plan" / "mobile" / "cluttered_room.yaml"
ROOMS = {"empty": None, "cluttered": CLUTTERED}
TOLERANCE = 0.01  # [m] placement's default
CELL = (0.01, 0.01, math.radians(1.0))  # the reference grid
REACH = (SHOULDER[0] - TOLERANCE, SHOULDER[0] + L1 + L2 + TOLERANCE)  # tool x in the base frame


@pytest.fixture(scope="module", params=sorted(ROOMS))
def room(request: pytest.FixtureRequest) -> tuple[str, MobileRobot, Reference]:
    scene = ROOMS[request.param]
    mobile = load_mobile(read_robot(DEFAULT_SPEC), scene=scene)
    return request.param, mobile, Reference(read_objects(scene), TOLERANCE)


def _cases(n: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Seeded targets over the room (some too high or low) and starts near the origin."""
    rng = np.random.default_rng(seed)
    targets = np.column_stack([rng.uniform(-2.5, 2.5, n), rng.uniform(-2.5, 2.5, n),
                               rng.uniform(-0.05, 1.0, n)])  # fmt: skip
    starts = np.column_stack([rng.uniform(-1, 1, n), rng.uniform(-1, 1, n),
                              rng.uniform(-math.pi, math.pi, n)])  # fmt: skip
    return list(zip(targets, starts, strict=True))


def _grid_reaches(ref: Reference, target: np.ndarray) -> np.ndarray | None:
    """A FEASIBLE pose of the reference grid for `target`, or None (every cell tried).

    Cells whose base-frame target lies off the arm's plane or reach by more than the
    tolerance (plus the reference's band) cannot be FEASIBLE and are skipped.
    """
    g = np.arange(-80, 81) * CELL[0]
    cx, cy = np.round(target[0] / CELL[0]) * CELL[0], np.round(target[1] / CELL[1]) * CELL[1]
    X, Y = np.meshgrid(cx + g, cy + g, indexing="ij")
    X, Y = X.ravel(), Y.ravel()
    picked = []
    for deg in range(360):
        yaw = math.radians(deg)
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = target[0] - X, target[1] - Y
        tx, ty = c * dx + s * dy, -s * dx + c * dy
        near = (np.abs(ty) <= TOLERANCE + REACH_BAND) & (tx >= REACH[0] - REACH_BAND)
        near &= tx <= REACH[1] + REACH_BAND
        picked.append(np.column_stack([X[near], Y[near], np.full(int(near.sum()), yaw)]))
    cells = np.concatenate(picked)
    for k in range(0, len(cells), 20_000):
        chunk = cells[k : k + 20_000]
        ok = ref.classify(chunk, target) == FEASIBLE
        if np.any(ok):
            return chunk[int(np.argmax(ok))]
    return None


def _deeply_inside(ref: Reference, target: np.ndarray) -> bool:
    """Whether the target lies deeper than the tolerance in an object (the reference's shapes)."""
    for _, obj in ref.objects:
        if isinstance(obj, Box):
            depth = float(np.min(np.minimum(target - obj.lo, obj.hi - target)))
        else:
            assert isinstance(obj, Cylinder)
            rho = math.hypot(target[0] - obj.centre[0], target[1] - obj.centre[1])
            depth = min(obj.radius - rho, obj.half - abs(target[2] - obj.centre[2]))
        if depth > TOLERANCE:
            return True
    return False


def _run(ref: Reference, target: np.ndarray, pose: np.ndarray, axis: int, sign: float) -> tuple[
    float, float]:  # fmt: skip
    """How far along `axis` the reference's FEASIBLE cells reach (surely, and at most)."""
    k = np.arange(1, 121)
    poses = np.repeat(pose[None, :], len(k), axis=0)
    poses[:, axis] += sign * k * CELL[axis]
    verdicts = ref.classify(poses, target)
    not_feasible = np.nonzero(verdicts != FEASIBLE)[0]
    infeasible = np.nonzero(verdicts == INFEASIBLE)[0]
    surely = (not_feasible[0] if len(not_feasible) else len(k)) * CELL[axis]
    at_most = (infeasible[0] if len(infeasible) else len(k)) * CELL[axis]
    return float(surely), float(at_most)


def _check(mobile: MobileRobot, ref: Reference, target: np.ndarray, start: np.ndarray) -> str:
    """'' when placement agrees with the reference for this target, else what differs."""
    try:
        p = place(mobile, target, start, tolerance=TOLERANCE)
    except PlacementError as exc:
        top = SHOULDER[2] + L1 + L2  # the closed form's highest tool point: the arm upright
        reasons = []
        if target[2] > top + TOLERANCE + REACH_BAND:
            reasons.append("above the tool's reach")
        if _deeply_inside(ref, target):
            reasons.append("inside")
        if reasons:  # either reason is right when both hold
            return "" if any(r in exc.reason for r in reasons) else f"reason: {exc.reason}"
        found = _grid_reaches(ref, target)
        if found is None:
            return ""
        return f"not placed ({exc.reason}) but the grid reaches it from {found}"
    pose = np.array(p.verdict.base)
    if ref.classify(pose[None, :], target)[0] == INFEASIBLE:
        return f"placed at {pose}, infeasible for the reference"
    _, tool = arm_points(p.verdict.q[None, :])  # the reported joints, closed-form kinematics
    c, s = math.cos(pose[2]), math.sin(pose[2])
    world = pose[:2] + np.array([c * tool[0, 0] - s * tool[0, 1], s * tool[0, 0] + c * tool[0, 1]])
    error = float(np.linalg.norm(np.append(world, tool[0, 2]) - target))
    if abs(error - p.verdict.error) > 1e-9:
        return f"tool error {p.verdict.error} reported, {error} by the closed form"
    bounds = ((p.region.x[0], p.region.x[1]), (p.region.y[0], p.region.y[1]),
              (p.region.yaw[0], p.region.yaw[1]))  # fmt: skip
    for axis in range(3):
        for sign, edge in (
            (-1.0, pose[axis] - bounds[axis][0]),
            (1.0, bounds[axis][1] - pose[axis]),
        ):
            surely, at_most = _run(ref, target, pose, axis, sign)
            if not (surely - CELL[axis] - 1e-9 <= edge <= at_most + CELL[axis] + 1e-9):
                return (f"region axis {axis} side {sign:+g}: {edge:.4f} beyond the grid's "
                        f"[{surely:.4f}, {at_most:.4f}] by more than one cell")  # fmt: skip
    return ""


def _agree(room: tuple[str, MobileRobot, Reference], n: int, seed: int) -> None:
    name, mobile, ref = room
    problems = []
    for target, start in _cases(n, seed):
        why = _check(mobile, ref, target, start)
        if why:
            problems.append(f"{name} target {np.round(target, 4).tolist()}: {why}")
    assert not problems, "\n".join(problems[:10])


def test_placement_agrees_with_the_grid(room: tuple[str, MobileRobot, Reference]) -> None:
    _agree(room, 60, seed=1)


# Both rooms: coal 3.0.3 called a cylinder 8-25 mm inside a box free while Pinocchio's
# collision requests had enable_contact=False (4 of the 1000 cluttered placements); plan.collision
# now asks for contacts, so the checker agrees with the grid's exact reference here too.
@pytest.mark.slow
@pytest.mark.parametrize("name", ["empty", "cluttered"])
def test_placement_agrees_with_the_grid_on_1000_targets(name: str) -> None:
    scene = ROOMS[name]
    mobile = load_mobile(read_robot(DEFAULT_SPEC), scene=scene)
    _agree((name, mobile, Reference(read_objects(scene), TOLERANCE)), 1000, seed=2)


def test_a_target_too_high_names_the_highest_point(
    room: tuple[str, MobileRobot, Reference],
) -> None:
    _, mobile, _ = room
    with pytest.raises(PlacementError) as err:
        place(mobile, (0.5, 0.5, 1.3))
    top = SHOULDER[2] + L1 + L2  # the arm straight up: the closed form's highest tool point
    assert f"z = {top:.3f} m" in err.value.reason


def test_a_target_inside_an_object_names_it() -> None:
    mobile = load_mobile(read_robot(DEFAULT_SPEC), scene=CLUTTERED)
    with pytest.raises(PlacementError) as err:
        place(mobile, (-1.0, 1.2, 0.25))  # the crate's centre (the scene file)
    assert err.value.blocking == "crate"


def test_verdicts_are_mostly_decided(room: tuple[str, MobileRobot, Reference]) -> None:
    """Around a placed pose the reference decides most cells (all AMBIGUOUS would test nothing)."""
    _, mobile, ref = room
    target = np.array([0.3, 0.2, 0.5])
    pose: np.ndarray = np.array(list(place(mobile, target).verdict.base))
    rng = np.random.default_rng(0)
    poses = pose + rng.uniform(-1, 1, (2000, 3)) * np.array([0.03, 0.03, math.radians(3)])
    verdicts = ref.classify(poses, target)
    assert np.mean(verdicts == AMBIGUOUS) < 0.1
    assert np.mean(verdicts == FEASIBLE) > 0.1 and np.mean(verdicts == INFEASIBLE) > 0.1
