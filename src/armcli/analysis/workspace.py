"""The arm's workspace: where its tool point can go within the joint limits.

The chain is the moving joints between the root and the tool point's link. Forward
kinematics (Pinocchio) of the zero pose, every corner of the range box when there are few
and seeded uniform draws of those joints (`robot.sampling.search_starts`) gives a cloud
of tool positions in the root frame; each extreme of the envelope is then refined by a
local search within the limits (`analysis.boxsearch`) from the best samples, so it does not
depend on a lucky draw:

- max reach: the largest distance from the shoulder (the origin of the chain's first
  moving joint) to the tool point;
- vertical: the highest and lowest tool point (root z);
- horizontal: the largest distance from the root's z axis.

Whether a point is reachable: its distance to the nearest sample, then damped least
squares inverse kinematics (clipped to the limits) from the nearest samples; the
residual is what is left of |p(q) - target| (reachable when under REACH_TOL).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.analysis.boxsearch import minimize_box
from armcli.robot import sampling
from armcli.robot.frames import joint_frame, link_frame
from armcli.robot.joints import Joint
from armcli.robot.model import Robot
from armcli.robot.sampling import REACH_DRAWS, SAMPLE_SEED
from armcli.robot.tool import ToolPoint

REFINE_FROM = 3  # local searches per extreme, from the best samples
REACH_TOL = 1e-3  # [m] an inverse-kinematics residual below this is reached
IK_SEEDS = 5  # nearest samples the inverse kinematics starts from
SEED_POOL = 50  # nearest samples the seeds are picked from
SEED_SPREAD = 0.1  # seeds differ by this share of the joint ranges (root mean square)
IK_ITERATIONS = 100
IK_DAMPING = 1e-3  # [m] damped least squares' lambda


@dataclass(frozen=True)
class Workspace:
    """The tool point's reach envelope in the root frame [m]."""

    point: str  # the tool point's label
    shoulder: tuple[float, float, float]  # [m] the chain's first moving joint's origin
    joints: tuple[str, ...]
    samples: int
    max_reach: float  # [m] from the shoulder
    max_height: float  # [m] root z
    min_height: float
    max_horizontal: float  # [m] from the root's z axis
    lower: tuple[float, float, float]  # [m] bounding box of the reachable points
    upper: tuple[float, float, float]
    reach_q: tuple[tuple[str, float], ...]  # where the max reach is


@dataclass(frozen=True)
class ReachPoint:
    """Whether a target point [m] (root frame) is reachable, and how close the arm gets."""

    target: tuple[float, float, float]
    reachable: bool
    residual: float  # [m] |p(q) - target| after inverse kinematics
    nearest_sample: float  # [m] distance to the nearest sampled tool position
    q: tuple[tuple[str, float], ...]  # the closest configuration found


class Chain:
    """Forward kinematics of the tool point over the chain's joints, and its Jacobian."""

    def __init__(
        self, robot: Robot, tool: ToolPoint, others: Mapping[str, float] | None = None
    ) -> None:
        """`others`: values [rad or m] of joints off the chain (neutral where silent)."""
        model = robot.model
        frame = link_frame(model, tool.link)
        if frame is None:
            raise ValueError(f"no link {tool.link!r} in the model")
        self.robot = robot
        self.model = model
        self.frame = frame
        self.xyz = np.asarray(tool.xyz, dtype=float)
        self.tool = tool
        jid = model.frames[self.frame].parentJoint
        path = []
        while jid > 0:
            path.append(jid)
            jid = model.parents[jid]
        ids = set(path)
        self.joints: tuple[Joint, ...] = tuple(
            j for j in robot.joints if model.getJointId(j.name) in ids
        )
        self.iv = [j.idx_v for j in self.joints]
        self.q0 = robot.q(others or {})
        self.box = sampling.bounds(self.joints)
        self.lower = np.array([lo for lo, _ in self.box])
        self.upper = np.array([hi for _, hi in self.box])

    def q(self, x: ArrayLike) -> NDArray[np.float64]:
        """The model's configuration with the chain's joints at x [rad or m]."""
        return self.robot.q(x, joints=self.joints, base=self.q0)

    def position(self, x: ArrayLike) -> NDArray[np.float64]:
        """The tool point [m] in the root frame."""
        return self.robot.point_position(self.tool.link, self.xyz, self.q(x))

    def jacobian(self, x: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(tool point [m], d point / dx (3, n))."""
        p, J = self.robot.jacobian(self.q(x), self.tool.link, self.xyz, self.iv)
        return p, J[:3]

    def shoulder(self) -> NDArray[np.float64]:
        """The origin [m] of the chain's first moving joint (fixed by everything above it)."""
        if not self.joints:
            return self.position([])
        first = joint_frame(self.model, self.joints[0].name)
        assert first is not None  # one of the model's joints
        return self.robot.frame_pose(first, self.q0)[:3, 3].copy()

    def names(self, x: ArrayLike) -> tuple[tuple[str, float], ...]:
        """The chain's joint values by name."""
        return tuple((jr.name, float(v)) for jr, v in zip(self.joints, np.asarray(x), strict=True))


@dataclass(frozen=True)
class Cloud:
    """Sampled configurations (N, n) and the tool positions they reach (N, 3) [m]."""

    x: NDArray[np.float64]
    p: NDArray[np.float64]


def sample(chain: Chain, n: int = REACH_DRAWS, seed: int = SAMPLE_SEED) -> Cloud:
    """The zero pose, the range box's corners and n seeded draws of the chain's joints."""
    rows = sampling.search_starts(chain.box, n, seed=seed)
    x = np.array(rows, dtype=float).reshape(len(rows), len(chain.joints))
    return Cloud(x, np.array([chain.position(r) for r in x]))


def envelope(chain: Chain, cloud: Cloud) -> Workspace:
    """The reach envelope: the cloud's extremes, each refined by a local search."""
    c = chain.shoulder()

    def far(x: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        p, J = chain.jacobian(x)
        d = p - c
        r = float(np.linalg.norm(d))
        return -r, -(d @ J) / max(r, 1e-12)

    def wide(x: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        p, J = chain.jacobian(x)
        r = float(np.hypot(p[0], p[1]))
        return -r, -(p[:2] @ J[:2]) / max(r, 1e-12)

    reach, x_reach = _refine(chain, cloud, far, -np.linalg.norm(cloud.p - c, axis=1))
    side, _ = _refine(chain, cloud, wide, -np.hypot(cloud.p[:, 0], cloud.p[:, 1]))
    # The box: each face refined as the height is (the cloud alone put TurtleBot3's
    # OpenMANIPULATOR-X x max 50 mm short of the brute-force value).
    lo, hi = np.zeros(3), np.zeros(3)
    for axis in range(3):
        hi[axis] = -_refine(chain, cloud, _along(chain, axis, 1.0), -cloud.p[:, axis])[0]
        lo[axis] = _refine(chain, cloud, _along(chain, axis, -1.0), cloud.p[:, axis])[0]
    return Workspace(
        point=chain.tool.label,
        shoulder=(float(c[0]), float(c[1]), float(c[2])),
        joints=tuple(jr.name for jr in chain.joints),
        samples=len(cloud.x),
        max_reach=-reach,
        max_height=float(hi[2]),
        min_height=float(lo[2]),
        max_horizontal=-side,
        lower=(float(lo[0]), float(lo[1]), float(lo[2])),
        upper=(float(hi[0]), float(hi[1]), float(hi[2])),
        reach_q=chain.names(x_reach),
    )


def _along(
    chain: Chain, axis: int, sign: float
) -> Callable[[NDArray[np.float64]], tuple[float, NDArray[np.float64]]]:
    """The objective -sign * p[axis] (minimised: the tool point's extreme along root `axis`)."""

    def f(x: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        p, J = chain.jacobian(x)
        return -sign * float(p[axis]), -sign * J[axis]

    return f


def _refine(
    chain: Chain, cloud: Cloud, fun: Any, values: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64]]:
    """The least value of `fun` from the cloud's best samples, searched within the limits."""
    k0 = int(np.argmin(values))
    best_f, best_x = float(values[k0]), cloud.x[k0]
    if not chain.joints:
        return best_f, best_x
    for k in np.argsort(values)[:REFINE_FROM]:
        res = minimize_box(fun, cloud.x[k], chain.lower, chain.upper)
        if res.f < best_f:
            best_f, best_x = res.f, res.x
    return best_f, best_x


def reach_point(chain: Chain, cloud: Cloud, target: ArrayLike) -> ReachPoint:
    """Whether the tool point can reach `target` [m]: nearest sample, then inverse kinematics."""
    t = np.asarray(target, dtype=float)
    d = np.linalg.norm(cloud.p - t, axis=1)
    best_r, best_x = math.inf, cloud.x[int(np.argmin(d))]
    for k in _seeds(chain, cloud, d):
        x, r = _ik(chain, cloud.x[k], t)
        if r < best_r:
            best_r, best_x = r, x
        if best_r < REACH_TOL * 1e-3:
            break
    return ReachPoint(
        target=(float(t[0]), float(t[1]), float(t[2])),
        reachable=best_r <= REACH_TOL,
        residual=best_r,
        nearest_sample=float(np.min(d)),
        q=chain.names(best_x),
    )


def _seeds(chain: Chain, cloud: Cloud, d: NDArray[np.float64]) -> list[int]:
    """IK_SEEDS samples near the target, each in another arm configuration.

    The nearest samples alone tend to be one configuration (one elbow, one wrist): their
    searches end in the same local minimum, which for a point out of reach was 12 mm
    farther than the closest a UR5 gets. A seed must differ from those taken by
    SEED_SPREAD of the joint ranges (root mean square); the nearest SEED_POOL are looked at.
    """
    span = np.maximum(chain.upper - chain.lower, 1e-9)
    taken: list[int] = []
    for k in np.argsort(d)[:SEED_POOL]:
        u = cloud.x[k] / span
        if all(np.sqrt(np.mean((u - cloud.x[j] / span) ** 2)) > SEED_SPREAD for j in taken):
            taken.append(int(k))
            if len(taken) == IK_SEEDS:
                break
    return taken


def _ik(chain: Chain, x0: NDArray[np.float64], target: NDArray[np.float64]) -> tuple[Any, float]:
    """Damped least squares on the tool position, clipped to the limits; (x, residual [m])."""
    x = np.array(x0, dtype=float)
    best_x, best_r = x.copy(), math.inf
    for _ in range(IK_ITERATIONS):
        p, J = chain.jacobian(x)
        e = target - p
        r = float(np.linalg.norm(e))
        if r < best_r:
            best_x, best_r = x.copy(), r
        if r < 1e-9 or not len(x):
            break
        step = J.T @ np.linalg.solve(J @ J.T + IK_DAMPING**2 * np.eye(3), e)
        x = np.clip(x + step, chain.lower, chain.upper)
    if best_r < REACH_TOL * 1e-3 or not len(x):
        return best_x, best_r
    # Clipping stalls damped least squares against a limit (TurtleBot3's OpenMANIPULATOR-X
    # missed a reachable point by 2.8 mm): a projected gradient search on |e|²/2 slides
    # along the limits to the closest point.

    def half_square(x: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        p, J = chain.jacobian(x)
        e = p - target
        return 0.5 * float(e @ e), J.T @ e

    res = minimize_box(half_square, best_x, chain.lower, chain.upper)
    r = math.sqrt(2.0 * max(res.f, 0.0))
    return (res.x, r) if r < best_r else (best_x, best_r)


def describe(ws: Workspace) -> str:
    """The envelope in one line, as `check` and `render --reach` print it."""
    box = " ".join(f"{a:.3f}..{b:.3f}" for a, b in zip(ws.lower, ws.upper, strict=True))
    return (
        f"reach of {ws.point} over {', '.join(ws.joints)}: max {ws.max_reach:.3f} m from the "
        f"shoulder ({', '.join(f'{v:.3f}' for v in ws.shoulder)}), height {ws.min_height:.3f}.."
        f"{ws.max_height:.3f} m, horizontal {ws.max_horizontal:.3f} m from the root's z axis; "
        f"box x y z {box} m ({ws.samples} samples, extremes refined)"
    )


def verdict(p: ReachPoint) -> str:
    """One point's verdict: reachable, or by how much it is missed, and the joints there."""
    xyz = ", ".join(f"{v:.3f}" for v in p.target)
    what = "reachable" if p.reachable else f"OUT OF REACH by {p.residual * 1e3:.1f} mm"
    q = ", ".join(f"{n}={v:.4g}" for n, v in p.q)
    return f"point ({xyz}): {what} (at {q})"
