"""The base poses placement tries, cheapest driving first.

An arm configuration q puts the tool at p(q) in the base frame. Standing the base so that
p(q) lands on the target leaves one freedom, the yaw: the base at (T_xy - R(yaw) p_xy(q),
yaw) for any yaw, the whole robot turned about the vertical through the target. So the
candidates are (configuration, yaw) pairs: configurations whose tool height matches the
target's, yaws every YAW_STEP. For a planar-reach arm the configurations come in closed
form (`PlanarArm.at_height`: the tool exactly at the target's height, both branches);
for another arm from a seeded sample of its joint box, nearest in height first, each then
corrected at its base pose by inverse kinematics (`Judge.nearest`).

Every candidate's driving cost (`plan.mobile.driving`) is computed at once; they are
handed out in cost order, a chunk at a time (a partial sort: most placements stop early).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from armcli.plan.mobile.driving import driving_cost
from armcli.plan.mobile.judge import Judge
from armcli.robot import sampling

# (planar arm: values of the first joint over its range, [rad] between candidate yaws): a
# coarse pass first; the fine one only when the coarse finds no pose (a sliver of free floor)
PASSES = ((46, math.radians(3.0)), (181, math.radians(0.5)))
CHUNK = 256  # candidates sorted at a time
ARC_SAMPLES = 181  # planar arm above or below its reach: samples per boundary arc
ARM_DRAWS = 2048  # other arms: seeded configurations sampled
ARM_KEPT = 48  # ... of which the nearest in height are candidates
HEIGHT_FIRST = 1e3  # [m of driving per m of tool miss]: the nearer approach always wins
TIER = 1e3  # [m of driving]: a planar family's tiers never mix
FAR = 900.0  # [m] a base pose beyond any scene: what fails there fails everywhere
OFF_PLANE = (-0.95, -0.5, 0.5, 0.95)  # shares of the tolerance a planar arm's base stands off


@dataclass(frozen=True)
class Family:
    """Arm configurations (K, n), their tool points (K, 3) [m, base frame], height misses [m]."""

    q: np.ndarray
    p: np.ndarray
    miss: np.ndarray  # [m] |tool z - target z| (0 at the target's height)
    lateral: np.ndarray | None = None  # base-frame direction the tool cannot move (planar arm)
    nearest: np.ndarray | None = None  # (K,) bool: the configuration is the pose's nearest
    heights: tuple[float, float] = (-np.inf, np.inf)  # [m] the lowest and highest tool point

    @property
    def lateral_xy(self) -> tuple[float, float]:
        """The lateral direction's x and y (0, 0 without one)."""
        if self.lateral is None:
            return 0.0, 0.0
        return float(self.lateral[0]), float(self.lateral[1])


def planar_family(judge: Judge, samples: int) -> Family:
    """Closed form: configurations at the target's height, each its poses' nearest approach."""
    arm = judge.mobile.planar
    assert arm is not None
    q, _ = arm.at_height(float(judge.target[2] - arm.shoulder[2]), samples)
    return Family(
        q,
        arm.points(q),
        np.zeros(len(q)),
        arm.axis,
        np.ones(len(q), dtype=bool),
        _planar_heights(judge),
    )


def boundary_family(judge: Judge) -> Family:
    """The reach boundary's configurations within the tolerance of the target's height.

    A target the tool only comes near (above the top of the reach, or one whose exact
    approaches all collide) is nearest to the reach's boundary from a pose that puts it
    beyond the reach: these configurations stand for those poses (judged afresh there,
    `Candidate.nearest` False). Tried only when the target's height finds no pose.
    """
    arm = judge.mobile.planar
    assert arm is not None
    boundary = []
    for start, k, span in arm.arcs():
        for t in np.linspace(0.0, span, ARC_SAMPLES):
            x = start.copy()
            x[k] += t
            boundary.append(x)
    qb = np.array(boundary)
    miss = np.abs(arm.points(qb)[:, 2] - judge.target[2])
    keep = miss <= judge.tolerance
    q = qb[keep]
    return Family(
        q, arm.points(q), miss[keep], arm.axis, np.zeros(len(q), dtype=bool), _planar_heights(judge)
    )


def _planar_heights(judge: Judge) -> tuple[float, float]:
    arm = judge.mobile.planar
    assert arm is not None
    lo, hi = arm.height_range()
    return float(arm.shoulder[2] + lo), float(arm.shoulder[2] + hi)


def sampled_family(judge: Judge, seed: int) -> Family:
    """Other arms: seeded configurations of the joint box, the nearest in height first.

    Only configurations that could stand anywhere (`standing`: no self-collision, not in the
    floor, stable) are kept, ARM_KEPT of them: a low target's nearest heights are often the
    arm folded into its own base.
    """
    robot = judge.arm_robot
    box = list(zip(robot.lower.tolist(), robot.upper.tolist(), strict=True))
    rows = np.array(sampling.search_starts(box, ARM_DRAWS, seed=seed), dtype=float)
    p = np.empty((len(rows), 3))
    for i, x in enumerate(rows):
        p[i] = robot.robot.tool_position(robot.q(x))
    miss = np.abs(p[:, 2] - judge.target[2])
    spread = _heights(judge)
    order = np.argsort(miss, kind="stable")
    kept: list[np.ndarray] = []
    for start in range(0, len(order), ARM_KEPT):
        k = order[start : start + ARM_KEPT]
        kept.append(k[_stands(judge, rows[k])])
        if sum(len(x) for x in kept) >= ARM_KEPT:
            break
    keep = np.concatenate(kept)[:ARM_KEPT]
    return Family(rows[keep], p[keep], miss[keep], heights=spread)


def _heights(judge: Judge) -> tuple[float, float]:
    """[m] the lowest and highest tool point: the workspace analysis' refined envelope.

    (analysis.workspace on the robot's own model, fixed root: samples, then a local search
    from the best.)
    """
    from armcli.analysis.workspace import Chain, envelope, sample
    from armcli.robot.model import Robot
    from armcli.robot.tool import tool_point

    robot_file = judge.mobile.robot_file
    plain = Robot.load(robot_file.robot, spec=robot_file.spec, strict=False)
    tool = tool_point(robot_file.robot, robot_file.spec)
    if tool is None:  # pragma: no cover - the mobile robot has a tool point
        return -np.inf, np.inf
    chain = Chain(plain, tool, dict(judge.arm_robot.rest))
    ws = envelope(chain, sample(chain))
    return ws.min_height, ws.max_height


def standing(judge: Judge, family: Family) -> Family:
    """The family without configurations that fail wherever the base stands.

    Self-collision, the arm in the floor and the tip-over margin do not depend on the base's
    pose: each configuration is checked once, with the base far from every scene object
    (FAR, on the same endless floor), instead of once per yaw. (Another arm's
    configurations only seed its inverse kinematics: there this is a filter of seeds.)
    """
    judged = np.ones(len(family.q), dtype=bool) if family.nearest is None else family.nearest
    ok = np.ones(len(family.q), dtype=bool)  # another pose's nearest approach: judged there
    ok[judged] = _stands(judge, family.q[judged])
    keep = np.nonzero(ok)[0]
    nearest = None if family.nearest is None else family.nearest[keep]
    return Family(
        family.q[keep], family.p[keep], family.miss[keep], family.lateral, nearest, family.heights
    )


def _stands(judge: Judge, qs: np.ndarray) -> np.ndarray:
    """(K,) bool: each configuration is stable and collision-free with the base at FAR."""
    out = np.zeros(len(qs), dtype=bool)
    for i, q in enumerate(qs):
        margin = judge.margin(q)
        if margin is not None and margin <= 0.0:
            continue
        out[i] = judge.mobile.checker.first_collision(judge.mobile.x((FAR, FAR, 0.0), q)) is None
    return out


@dataclass(frozen=True)
class Candidate:
    """One base pose to judge, with the configuration it was made for and its cost."""

    base: tuple[float, float, float]
    q: np.ndarray
    miss: float  # [m] how far the configuration's tool is from the target at this pose
    cost: float  # [m] wheel travel from the start
    nearest: bool  # q is the nearest approach at this pose (a planar arm at the exact height)


def ordered(
    family: Family,
    target: np.ndarray,
    start: ArrayLike,
    turn_radius: float,
    step: float,
    tolerance: float,
) -> Iterator[list[Candidate]]:
    """Every (configuration, yaw every `step`) of the family as a base pose, in chunks.

    A planar family's poses come in tiers, each cheapest driving first: at the target's
    height on the plane, then stood off sideways by OFF_PLANE shares of the tolerance (the
    tool misses by that much), then the reach boundary's near misses. Poses whose miss is
    beyond the tolerance are left out. Another arm's come nearest in height first. The
    stand-off tier's poses are costed only once the plane's are used up (most placements
    stop in the first chunk): a tier never mixes with the next (TIER).
    """
    offsets = np.array([0.0])
    if family.lateral is not None:
        offsets = np.array([0.0, *(f * tolerance for f in OFF_PLANE)])
    tiers = [offsets]
    if family.nearest is not None and bool(np.all(family.nearest)) and len(offsets) > 1:
        tiers = [offsets[:1], offsets[1:]]  # the plane's tier 0, the stand-offs' tier 1
    for offs in tiers:
        yield from _chunks(family, offs, target, start, turn_radius, step, tolerance)


def _chunks(
    family: Family,
    offsets: np.ndarray,
    target: np.ndarray,
    start: ArrayLike,
    turn_radius: float,
    step: float,
    tolerance: float,
) -> Iterator[list[Candidate]]:
    """`ordered`'s chunks over the given sideways offsets [m] (see there)."""
    yaw = np.arange(-math.pi, math.pi, step)
    c, s = np.cos(yaw)[None, None, :], np.sin(yaw)[None, None, :]
    px = family.p[None, :, 0:1] + offsets[:, None, None] * family.lateral_xy[0]
    py = family.p[None, :, 1:2] + offsets[:, None, None] * family.lateral_xy[1]
    bx = target[0] - (c * px - s * py)  # (offsets, configurations, yaws)
    by = target[1] - (s * px + c * py)
    yaws = np.broadcast_to(yaw, bx.shape)
    drive = driving_cost(start, bx, by, yaws, turn_radius).ravel()
    miss = np.sqrt(family.miss[None, :] ** 2 + offsets[:, None] ** 2)  # (offsets, configurations)
    near = np.ones(len(family.q), bool) if family.nearest is None else family.nearest
    if family.nearest is not None:  # the miss is the tool's: beyond the tolerance, no pose
        tier = np.where(near[None, :], (offsets[:, None] != 0).astype(float), 2.0)
        key = np.where(miss <= tolerance, TIER * tier, np.inf)
    else:  # a seed's height miss: the inverse kinematics at the pose corrects it
        key = HEIGHT_FIRST * miss
    left = drive + np.repeat(key.ravel(), len(yaw))
    n_yaw, n_q = len(yaw), len(family.q)
    while True:
        k = min(CHUNK, int(np.count_nonzero(np.isfinite(left))))
        if k == 0:
            return
        idx = np.argpartition(left, k - 1)[:k] if k < len(left) else np.arange(len(left))
        idx = idx[np.argsort(left[idx], kind="stable")]
        idx = idx[np.isfinite(left[idx])]
        left[idx] = np.inf
        chunk = []
        for flat in idx:
            dq, j = divmod(int(flat), n_yaw)
            d, i = divmod(dq, n_q)
            chunk.append(
                Candidate(
                    (float(bx.flat[flat]), float(by.flat[flat]), float(yaw[j])),
                    family.q[i],
                    float(miss[d, i]),
                    float(drive[flat]),
                    family.nearest is not None and bool(near[i]),
                )
            )
        yield chunk
