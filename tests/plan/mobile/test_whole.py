"""`plan --base` on the course robot: the base path against an ideal unicycle and an
independent collision check, the files `simulate` reads, the arm held until the base stops.

The commands written to cmd_vel.yaml are integrated here as an ideal unicycle (each held
command an exact arc) from the base's start: they must end at the placed pose to 1 mm.
Along that integrated motion, sampled every few millimetres, the robot (the base's shapes
and the arm in its travel pose, tests/plan/mobile/reference.py) must never meet a scene
object, by the reference's own shapes and tests.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from armcli.drive.cmdvel import load_cmd_vel
from armcli.errors import PlanningError
from armcli.plan.api import PlanOptions
from armcli.plan.mobile.basefiles import cmd_vel_of, cmd_vel_yaml
from armcli.plan.mobile.virtual import MobileRobot, load_mobile
from armcli.plan.mobile.whole import BaseGoal, Drive, WholePlan, files, plan_drive, plan_whole
from armcli.trajectory.message import load_trajectory
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC
from tests.plan.mobile.reference import INFEASIBLE, Reference, read_objects
from tests.plan.mobile.test_place import CLUTTERED

REACHED = 1e-3  # [m] the integrated commands end this near the placed pose (the bound)
# specs/my_robot.yaml: the wheel joints at (-0.15, +-0.225) in base_link, whose origin is
# above base_footprint's: /cmd_vel moves the wheels' midpoint, 0.15 m behind base_footprint.
AXLE = np.array([-0.15, 0.0])
YAW_REACHED = 1e-3  # [rad]
SAMPLES_PER_COMMAND = 3  # poses checked per held command (<= 2 mm apart at 0.3 m/s, 50 Hz)
# Targets around the cluttered room's objects (its file): on the table, beside the crate,
# the bin and the cabinet, under the shelf, behind the pillar; and starts across the room.
TARGETS = [(1.35, 0.0, 0.5), (1.3, -0.25, 0.48), (2.0, 0.4, 0.5), (-1.0, 0.8, 0.55),
           (0.9, 1.0, 0.5), (2.0, -1.2, 0.85), (-2.0, 0.0, 0.4), (-1.5, -1.4, 0.3),
           (0.3, -1.5, 0.62), (-0.6, 1.2, 0.3)]  # fmt: skip
STARTS = [(0.0, 0.0, 0.0), (-0.5, -0.5, 1.0), (0.6, 0.6, -2.0)]


@pytest.fixture(scope="module")
def cluttered() -> MobileRobot:
    return load_mobile(read_robot(DEFAULT_SPEC), scene=CLUTTERED)


def shifted(pose: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Poses (..., 3) of the point `offset` (base frame) of bases at `pose`."""
    c, s = np.cos(pose[..., 2]), np.sin(pose[..., 2])
    x = pose[..., 0] + c * offset[0] - s * offset[1]
    y = pose[..., 1] + s * offset[0] + c * offset[1]
    return np.stack([x, y, pose[..., 2]], axis=-1)


def integrate(commands: list[dict], start: tuple[float, float, float]) -> tuple[
    np.ndarray, np.ndarray]:  # fmt: skip
    """Final pose and poses along the way of an ideal unicycle given the held commands."""
    x, y, th = start
    seen = []
    for k, c in enumerate(commands):
        t = c["time_from_start"]["sec"] + 1e-9 * c["time_from_start"]["nanosec"]
        if k + 1 == len(commands):
            break
        nxt = commands[k + 1]["time_from_start"]
        dt = nxt["sec"] + 1e-9 * nxt["nanosec"] - t
        v, w = c["linear"]["x"], c["angular"]["z"]
        for s in np.linspace(0.0, dt, SAMPLES_PER_COMMAND + 1)[1:]:
            if abs(w) > 1e-12:  # the exact arc
                px = x + v / w * (math.sin(th + w * s) - math.sin(th))
                py = y - v / w * (math.cos(th + w * s) - math.cos(th))
            else:
                px, py = x + v * s * math.cos(th), y + v * s * math.sin(th)
            seen.append((px, py, th + w * s))
        x, y, th = seen[-1]
    return np.array([x, y, th]), np.array(seen).reshape(-1, 3)


def _goal(target: tuple[float, ...], start: tuple[float, ...]) -> BaseGoal:
    return BaseGoal((target[0], target[1], target[2]), (start[0], start[1], start[2]))


def _plan(mobile: MobileRobot, target: tuple[float, ...], start: tuple[float, ...]) -> WholePlan:
    return plan_whole(mobile, _goal(target, start), PlanOptions(seed=0))


def _drive(mobile: MobileRobot, target: tuple[float, ...], start: tuple[float, ...]) -> Drive:
    return plan_drive(mobile, _goal(target, start))


@pytest.mark.parametrize(
    "start", [STARTS[0], *(pytest.param(s, marks=pytest.mark.slow) for s in STARTS[1:])]
)
def test_the_base_path_reaches_the_pose_and_touches_nothing(
    cluttered: MobileRobot, start: tuple[float, float, float], tmp_path: Path
) -> None:
    ref = Reference(read_objects(CLUTTERED), 0.01)
    detours = 0
    for target in TARGETS:
        w = _drive(cluttered, target, start)
        commands = yaml.safe_load(cmd_vel_yaml(w.timing))["commands"]
        x0, y0, th0 = shifted(np.array(start, dtype=float), AXLE)  # the commands' point
        end, along = integrate(commands, (x0, y0, th0))
        along = shifted(along, -AXLE)  # the base's poses, for the collision check
        goal = shifted(np.array(w.placement.verdict.base), AXLE)
        assert np.hypot(*(end[:2] - goal[:2])) <= REACHED, target
        assert abs(math.remainder(end[2] - goal[2], 2 * math.pi)) <= YAW_REACHED, target
        travel = np.repeat(w.travel[None, :], len(along), axis=0)
        hits = ref.collides(along, travel) == INFEASIBLE
        assert not np.any(hits), f"{target}: touches an object at {along[np.argmax(hits)]}"
        detours += len(w.path.legs) > 1
    assert detours >= 1  # some paths go around an object: the roadmap is exercised


def test_the_files_are_what_simulate_reads(cluttered: MobileRobot, tmp_path: Path) -> None:
    w = _plan(cluttered, TARGETS[0], STARTS[0])
    for path, data in files(w, tmp_path, "test").items():
        path.write_bytes(data)
    cmd = load_cmd_vel(tmp_path / "cmd_vel.yaml")
    assert cmd.duration == pytest.approx(w.timing.duration, abs=1e-9)
    lows, highs = w.arm.timed.positions.min(0) - 1, w.arm.timed.positions.max(0) + 1
    limits = {j: (lo, hi) for j, lo, hi in zip(cluttered.arm, lows, highs, strict=True)}
    arm = load_trajectory(tmp_path / "arm.yaml", limits)
    held = arm.times <= w.timing.duration + 1e-9  # the arm waits for the base
    assert np.allclose(arm.positions[held], w.travel)
    assert arm.times[-1] == pytest.approx(w.timing.duration + w.arm.duration_s, abs=1e-6)
    path = yaml.safe_load((tmp_path / "path.yaml").read_text())
    last = path["poses"][-1]["pose"]["position"]
    assert math.hypot(last["x"] - w.placement.verdict.base[0],
                      last["y"] - w.placement.verdict.base[1]) < 1e-9  # fmt: skip


def test_the_unparsed_commands_are_the_file_read_back(
    cluttered: MobileRobot, tmp_path: Path
) -> None:
    """`--execute` runs cmd_vel_of(timing) instead of re-reading its own cmd_vel.yaml."""
    for target, start in zip(TARGETS[:3], STARTS[:3], strict=True):
        w = _plan(cluttered, target, start)
        (tmp_path / "cmd_vel.yaml").write_bytes(cmd_vel_yaml(w.timing))
        read = load_cmd_vel(tmp_path / "cmd_vel.yaml")  # the reference: the file's parser
        given = cmd_vel_of(w.timing)
        for field in ("times", "linear", "angular"):
            a, b = getattr(read, field), getattr(given, field)
            assert a.dtype == b.dtype and np.array_equal(a, b)  # value for value
            assert np.array_equal(np.signbit(a), np.signbit(b))  # -0.0 written as 0.0
        assert np.any(read.linear[:, 0] != 0.0) or np.any(read.angular[:, 2] != 0.0)


def test_the_wheels_stay_within_their_limits(cluttered: MobileRobot) -> None:
    w = _drive(cluttered, TARGETS[3], STARTS[1])
    _, lin, ang = w.timing.commands()
    lim = w.timing.limits
    rim = np.abs(lin) + lim.half_track * np.abs(ang)  # the faster wheel's rim speed
    assert np.max(rim) <= lim.speed + 1e-9
    steps = np.abs(np.diff(np.concatenate([[0.0], lin, [0.0]]))) + lim.half_track * np.abs(
        np.diff(np.concatenate([[0.0], ang, [0.0]])))  # fmt: skip
    # a mean over one period of a ramp at `accel` changes by at most accel * period per period
    assert np.max(steps) <= lim.accel * lim.period + 1e-9


def test_an_arm_failure_names_the_arm_and_the_parked_pose(
    cluttered: MobileRobot, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`plan --base` plans twice (the base, then the arm there): the reason says which failed."""
    import armcli.plan.mobile.whole as whole

    def no_path(*_args: object) -> None:
        raise PlanningError("no-path", "no collision-free path found within 1 s")

    monkeypatch.setattr(whole, "plan_motion", no_path)
    with pytest.raises(PlanningError) as caught:
        _plan(cluttered, (1.35, 0.0, 0.5), (0.0, 0.0, 0.0))
    assert caught.value.kind == "no-path"
    parked = _drive(cluttered, (1.35, 0.0, 0.5), (0.0, 0.0, 0.0)).placement.verdict.base
    assert str(caught.value) == (
        f"the arm, with the base parked at ({parked[0]:.3f}, {parked[1]:.3f}) m, "
        f"{math.degrees(parked[2]):.1f} deg: no collision-free path found within 1 s"
    )
