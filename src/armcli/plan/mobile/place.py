"""`armcli place`: where the base must stand for the tool to reach a point, least driving first.

`place` judges candidate base poses (`plan.mobile.candidates`) in the order of the
driving they cost from the start, and returns the first that serves the target
(`plan.mobile.judge`: reachable within the tolerance, collision-free, stable), with the
region around it (`plan.mobile.region`). A target nothing can serve raises
PlacementError with the reason: above or below the tool's reach (the highest or lowest
point it reaches), inside an object, or the object that blocks every pose.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from armcli.errors import InputError, PlanningError
from armcli.plan.mobile.candidates import (
    PASSES,
    Candidate,
    Family,
    boundary_family,
    ordered,
    planar_family,
    sampled_family,
    standing,
)
from armcli.plan.mobile.driving import DEFAULT_TURN_RADIUS
from armcli.plan.mobile.judge import Judge, Verdict
from armcli.plan.mobile.objects import containing
from armcli.plan.mobile.region import Region, region
from armcli.plan.mobile.virtual import FLOOR, MobileRobot

TOLERANCE = 0.01  # [m] the tool within this of the target counts as reaching it
MAX_CHECKS = 20_000  # collision checks before a placement gives up (a sliver of free floor)


class PlacementError(PlanningError):
    """No base pose serves the target; `reason` says why in one line."""

    def __init__(self, message: str, *, blocking: str | None = None) -> None:
        super().__init__("place", message)
        self.blocking = blocking


@dataclass(frozen=True)
class Placement:
    """The chosen base pose, the arm there, and the region around it."""

    verdict: Verdict  # base (x, y, yaw), q, tool error, tip margin
    joints: tuple[str, ...]  # the arm's, in q's order
    region: Region
    cost: float  # [m] wheel travel from the start, rotate-drive-rotate
    method: str  # "closed form" (planar-reach arm) or "sampled"
    checks: int  # collision checks made
    time_s: float  # [s] the placement's own time (the robot loaded before)


def turn_radius(mobile: MobileRobot) -> float:
    """[m] half the wheel separation (what a turn in place costs per radian of yaw)."""
    spec = mobile.robot_file.spec
    dd = spec.mobile_base.diff_drive if spec is not None and spec.mobile_base else None
    return 0.5 * float(dd.wheel_separation) if dd is not None else DEFAULT_TURN_RADIUS


def _values(name: str, given: ArrayLike, count: int) -> np.ndarray:
    v = np.asarray(given, dtype=float).reshape(-1)
    if v.shape != (count,) or not np.all(np.isfinite(v)):
        raise InputError(f"give {count} finite numbers", field=name)
    return v


def place(
    mobile: MobileRobot,
    target: ArrayLike,
    start: ArrayLike = (0.0, 0.0, 0.0),
    *,
    tolerance: float = TOLERANCE,
    seed: int = 0,
    park: Callable[[tuple[float, float, float]], bool] | None = None,
    accept: Callable[[Verdict], bool] | None = None,
) -> Placement:
    """The base pose of least driving from which the tool reaches `target`.

    `target` (x, y, z) [m] and `start` (x, y, yaw) [m, m, rad] in the world frame.
    PlacementError with the reason when no pose serves. `park(base)`: a further condition
    on every pose judged (the region's too); `accept(verdict)`: one on the chosen pose only
    (a pose it refuses is passed over for the next).
    """
    t0 = time.perf_counter()
    goal, begin = _values("target", target, 3), _values("start", start, 3)
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise InputError(
            f"must be a positive number of metres, got {tolerance!r}", field="tolerance"
        )
    inside = containing(mobile.scene, goal, tolerance)
    if inside is not None:
        raise PlacementError(
            f"the target is inside {inside}: no pose of the tool can reach it", blocking=inside
        )
    judge = Judge(mobile, goal, tolerance, park)
    best, tally = None, Counter[str]()
    for samples, step in PASSES:
        judge.checks = 0  # each pass has its budget (MAX_CHECKS)
        for family in _families(judge, samples, seed):
            _refuse_out_of_reach(mobile, judge, family)
            family = standing(judge, family)
            best, more = _search(judge, family, begin, turn_radius(mobile), step, accept)
            tally += more
            if best is not None:
                break
        if best is not None or mobile.planar is None:
            break
    if best is None:
        raise _blocked(mobile, tally)
    verdict, cost = best
    around = region(judge, verdict)
    return Placement(
        verdict,
        mobile.arm,
        around,
        cost,
        "closed form" if mobile.planar is not None else "sampled",
        judge.checks,
        time.perf_counter() - t0,
    )


def _families(judge: Judge, samples: int, seed: int) -> Iterator[Family]:
    """A planar arm's exact heights, then its reach boundary's near misses; another arm's."""
    if judge.mobile.planar is None:
        yield sampled_family(judge, seed)
        return
    yield planar_family(judge, samples)
    yield boundary_family(judge)


def _refuse_out_of_reach(mobile: MobileRobot, judge: Judge, family: Family) -> None:
    """Above or below the tool's reach: the highest (lowest) point it reaches.

    A planar arm's reach is exact (`PlanarArm.height_range`); another arm's is the
    workspace analysis' envelope.
    """
    bottom, top = family.heights
    z = float(judge.target[2])
    if bottom - judge.tolerance <= z <= top + judge.tolerance:
        return
    about = "" if mobile.planar is not None else "about "
    if z > top:
        raise PlacementError(
            f"the target z = {z:.3f} m is above the tool's reach: the highest "
            f"point it reaches is {about}z = {top:.3f} m"
        )
    raise PlacementError(
        f"the target z = {z:.3f} m is below the tool's reach: the lowest "
        f"point it reaches is {about}z = {bottom:.3f} m"
    )


def _search(
    judge: Judge,
    family: Family,
    start: np.ndarray,
    radius: float,
    step: float,
    accept: Callable[[Verdict], bool] | None,
) -> tuple[tuple[Verdict, float] | None, Counter[str]]:
    """The first serving (and accepted) candidate in order, and why others were not."""
    tally: Counter[str] = Counter()
    for chunk in ordered(family, judge.target, start, radius, step, judge.tolerance):
        for c, v in zip(chunk, _verdicts(judge, chunk), strict=False):
            if judge.checks >= MAX_CHECKS:
                return None, tally
            if v.ok and (accept is None or accept(v)):
                return (v, c.cost), tally
            tally[_blocker(judge.mobile, v) if not v.ok else "path"] += 1
    return None, tally


def _verdicts(judge: Judge, chunk: list[Candidate]) -> Iterator[Verdict]:
    """Each candidate's verdict with the arm at its nearest approach from that pose.

    A planar arm's configuration at the target's exact height is that approach already
    (stood off sideways, it misses by the stand-off); a planar arm's other candidates get
    theirs in one batch (`Judge.reach`), another arm's one by one (inverse kinematics).
    """
    later = [c for c in chunk if not c.nearest]
    batch = judge.mobile.planar is not None and bool(later)
    found = {id(c): k for k, c in enumerate(later)}
    if batch:
        q, errors = judge.reach(np.array([c.base for c in later]), later[0].q)
    for c in chunk:
        if c.nearest:
            yield judge.judge(c.base, c.q, c.miss)
        elif batch:
            k = found[id(c)]
            yield judge.best(c.base, q[k], errors[k])
        else:
            yield judge.at(c.base, c.q)


def _blocker(mobile: MobileRobot, v: Verdict) -> str:
    """What kept a pose from serving: an object's id, `self`, `tip` or `reach`."""
    if v.why != "collision" or v.blocked is None:
        return v.why
    objects = {o.id for o in mobile.scene.objects} | {FLOOR}
    hit = [name for name in v.blocked if name in objects]
    return hit[0] if hit else "self"


def _blocked(mobile: MobileRobot, tally: Counter[str]) -> PlacementError:
    total = sum(tally.values())
    if not total:
        return PlacementError("no base pose brings the tool within reach of the target")
    what, count = tally.most_common(1)[0]
    share = f"{count} of the {total} poses tried"
    if what == "tip":
        return PlacementError(f"the robot would tip over at every pose that reaches ({share})")
    if what == "self":
        return PlacementError(
            f"the arm collides with the robot at every pose that reaches ({share})"
        )
    if what == "reach":
        return PlacementError(f"the tool cannot come within reach of the target ({share})")
    if what == "park":
        return PlacementError(
            f"the base cannot stand at any pose that reaches the target with "
            f"the arm in its travel configuration ({share})"
        )
    if what == "path":
        return PlacementError(
            f"no path for the base leads to a pose that reaches the target ({share})"
        )
    return PlacementError(
        f"{what} blocks every base pose that reaches the target ({share} collide with it)",
        blocking=what,
    )
