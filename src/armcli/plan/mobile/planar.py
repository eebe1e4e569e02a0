"""A planar-reach arm in closed form: two revolute joints about parallel horizontal axes.

Such an arm (the course robot's) moves its tool point only in one vertical plane of the
base: the point stays at a fixed distance `offset` along the axis from the shoulder, and
its in-plane coordinates (u horizontal, w up, from the shoulder) are those of a planar
two-link chain, p = R(q1) (l1 + R(q2) l2), l1 and l2 the links' in-plane vectors at zero.
Inverse kinematics is the law of cosines (both elbow branches); the reachable set within
the joint limits is bounded by arcs (each joint at a limit, the elbow stretched or folded),
so the nearest reachable point of a target outside it is the nearest point of those arcs.

`planar_arm` decides from the model (the joints' axes in the base frame at zero), not
from names, whether an arm is one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from armcli.plan.robot import PlanRobot

PARALLEL_TOL = 1e-6  # |a1 x a2| and |a · z| below this: parallel axes, horizontal axis
TWO_PI = 2.0 * math.pi


def _rot(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def into_range(angle: float, lo: float, hi: float) -> float | None:
    """`angle` shifted by whole turns into [lo, hi], nearest to it; None when no turn fits."""
    k = math.ceil((lo - angle) / TWO_PI - 1e-12)
    shifted = angle + k * TWO_PI
    return shifted if shifted <= hi + 1e-12 else None


@dataclass(frozen=True)
class PlanarArm:
    """The closed form of a planar-reach arm; positions in the base frame [m]."""

    joints: tuple[str, str]
    shoulder: np.ndarray  # (3,) the first joint's origin
    axis: np.ndarray  # (3,) the joints' common axis, horizontal
    e_u: np.ndarray  # (3,) the plane's horizontal direction: (e_u, z, axis) right-handed
    offset: float  # [m] the tool point's distance from the shoulder along the axis
    l1: np.ndarray  # (2,) in-plane (u, w) vector shoulder -> elbow at q = 0
    l2: np.ndarray  # (2,) elbow -> tool point at q = 0
    planned: PlanRobot  # whose planning limits bound the joints (a continuous one: ±pi)

    @cached_property
    def lower(self) -> np.ndarray:
        """(2,) [rad] the joints' lower limits, as the planner reads them (`PlanRobot.lower`)."""
        return np.array([self.planned.lower[self.planned.joints.index(j)] for j in self.joints])

    @cached_property
    def upper(self) -> np.ndarray:
        """(2,) [rad] the joints' upper limits (`PlanRobot.upper`)."""
        return np.array([self.planned.upper[self.planned.joints.index(j)] for j in self.joints])

    def plane(self, q: ArrayLike) -> np.ndarray:
        """In-plane (u, w) [m] of the tool point from the shoulder at joint values `q`."""
        x = np.asarray(q, dtype=float)
        out: np.ndarray = _rot(x[0]) @ (self.l1 + _rot(x[1]) @ self.l2)
        return out

    def point(self, q: ArrayLike) -> np.ndarray:
        """The tool point [m] in the base frame."""
        out: np.ndarray = self.points(np.asarray(q, dtype=float)[None, :])[0]
        return out

    def points(self, q: np.ndarray) -> np.ndarray:
        """Tool points (K, 3) [m] in the base frame at joint values q (K, 2)."""
        c1, s1 = np.cos(q[:, 0]), np.sin(q[:, 0])
        c12, s12 = np.cos(q[:, 0] + q[:, 1]), np.sin(q[:, 0] + q[:, 1])
        (a, b), (c, d) = self.l1, self.l2
        u = c1 * a - s1 * b + c12 * c - s12 * d
        w = s1 * a + c1 * b + s12 * c + c12 * d
        z = np.array([0.0, 0.0, 1.0])
        base = self.shoulder + self.offset * self.axis
        return np.asarray(base + u[:, None] * self.e_u + w[:, None] * z)

    def coordinates(self, p: np.ndarray) -> tuple[float, float, float]:
        """(u, w, lateral) of a base-frame point: in-plane and off the plane [m]."""
        d = np.asarray(p, dtype=float) - self.shoulder
        return float(d @ self.e_u), float(d[2]), float(d @ self.axis) - self.offset

    def ik_batch(self, u: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Both elbow branches at once: q (N, 2, 2) [point, branch, joint], ok (N, 2).

        The law of cosines; a branch is ok when the point is within reach and both of its
        joints fit their limits after whole turns.
        """
        L1, L2 = float(np.hypot(*self.l1)), float(np.hypot(*self.l2))
        phi1, phi2 = math.atan2(self.l1[1], self.l1[0]), math.atan2(self.l2[1], self.l2[0])
        c = (u * u + w * w - L1 * L1 - L2 * L2) / (2.0 * L1 * L2)
        within = np.abs(c) <= 1.0 + 1e-12
        beta = np.arccos(np.clip(c, -1.0, 1.0))
        q = np.empty((len(u), 2, 2))
        ok = np.empty((len(u), 2), dtype=bool)
        for k, b in enumerate((beta, -beta)):
            alpha = np.arctan2(w, u) - np.arctan2(L2 * np.sin(b), L1 + L2 * np.cos(b))
            fits = within & ((k == 0) | (beta > 0))  # a stretched elbow has one branch
            for j, angle in enumerate((alpha - phi1, b - phi2 + phi1)):
                lo, hi = self.lower[j], self.upper[j]
                shifted = angle + np.ceil((lo - angle) / TWO_PI - 1e-12) * TWO_PI
                q[:, k, j] = shifted
                fits &= shifted <= hi + 1e-12
            ok[:, k] = fits
        return q, ok

    def ik(self, u: float, w: float) -> list[np.ndarray]:
        """Joint values within the limits putting the tool at (u, w): both elbow branches."""
        q, ok = self.ik_batch(np.array([u]), np.array([w]))
        return [q[0, k] for k in range(2) if ok[0, k]]

    def arcs(self) -> list[tuple[np.ndarray, int, float]]:
        """The reachable set's boundary arcs: one joint held, the other over its range.

        Held: the first joint at a limit, or the second at a limit, stretched or folded
        (the singular configurations). Each arc is (q at its start, the moving joint,
        its span [rad]): q(t) = start with the moving joint advanced by t in [0, span].
        """
        lo, hi = self.lower, self.upper
        phi1, phi2 = math.atan2(self.l1[1], self.l1[0]), math.atan2(self.l2[1], self.l2[0])
        held2 = [lo[1], hi[1]]
        for special in (phi1 - phi2, phi1 - phi2 + math.pi):  # stretched, folded
            inside = into_range(special, lo[1], hi[1])
            if inside is not None:
                held2.append(inside)
        span1, span2 = float(hi[0] - lo[0]), float(hi[1] - lo[1])
        out = [(np.array([q1, lo[1]]), 1, span2) for q1 in (lo[0], hi[0])]
        out += [(np.array([lo[0], q2]), 0, span1) for q2 in held2]
        return out

    def _circle(self, arc: tuple[np.ndarray, int, float]) -> tuple[np.ndarray, float, float]:
        """(centre (u, w), radius, direction angle at the arc's start) of an arc's circle."""
        q0, k, _ = arc
        if k == 0:  # q2 held: about the shoulder, at angle q1 + angle(l1 + R(q2) l2)
            v = self.l1 + _rot(q0[1]) @ self.l2
            return np.zeros(2), float(np.hypot(*v)), float(q0[0] + math.atan2(v[1], v[0]))
        centre = _rot(q0[0]) @ self.l1  # q1 held: about the elbow, at angle q1 + q2 + angle(l2)
        start = float(q0[0] + q0[1] + math.atan2(self.l2[1], self.l2[0]))
        return centre, float(np.hypot(*self.l2)), start

    @cached_property
    def _boundary(self) -> tuple[np.ndarray, ...]:
        """The arcs as arrays: start q (A, 2), moving joint, span, centre (A, 2), radius, angle."""
        arcs = self.arcs()
        circles = [self._circle(a) for a in arcs]
        return (
            np.array([a[0] for a in arcs]),
            np.array([a[1] for a in arcs]),
            np.array([a[2] for a in arcs]),
            np.array([c[0] for c in circles]),
            np.array([c[1] for c in circles]),
            np.array([c[2] for c in circles]),
        )

    def nearest_batch(self, u: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per in-plane point (u, w) [m]: q (N, 2, 2) and in-plane misses (N, 2) [m], per branch.

        The exact branches when the point is reachable within the limits (miss 0; a branch
        out of its limits: miss inf); otherwise the nearest point of the boundary arcs in
        the first slot (on each arc the circle's point toward the target if the arc passes
        it, else the arc's nearer end by angle) and inf in the second.
        """
        q, ok = self.ik_batch(u, w)
        miss = np.where(ok, 0.0, np.inf)
        out = ~ok.any(axis=1)
        if np.any(out):
            q0, k, span, centre, radius, start = self._boundary
            du = u[out, None] - centre[None, :, 0]  # (M, A)
            dw = w[out, None] - centre[None, :, 1]
            t = np.mod(np.arctan2(dw, du) - start, TWO_PI)  # ahead of each arc's start
            past = t > span
            t = np.where(past & (TWO_PI - t < t - span), 0.0, np.where(past, span, t))
            a = start + t
            gap = np.hypot(
                centre[:, 0] + radius * np.cos(a) - u[out, None],
                centre[:, 1] + radius * np.sin(a) - w[out, None],
            )
            best = np.argmin(gap, axis=1)
            rows = np.arange(len(best))
            near = q0[best].copy()
            near[rows, k[best]] += t[rows, best]
            q[out, 0] = near
            miss[out, 0] = gap[rows, best]
        return q, miss

    def nearest(self, u: float, w: float) -> list[np.ndarray]:
        """Joint values within the limits bringing the tool nearest to (u, w) in the plane.

        The exact solutions when there are any (both branches), else the nearest point
        of the reachable set (`nearest_batch`).
        """
        q, miss = self.nearest_batch(np.array([u]), np.array([w]))
        return [q[0, k] for k in range(2) if np.isfinite(miss[0, k])]

    def height_range(self) -> tuple[float, float]:
        """The lowest and highest in-plane w [m] the tool reaches within the limits.

        A linear function's extremes over the reachable set lie on its boundary arcs: on
        each, the circle's top or bottom when the arc passes it, else an end.
        """
        lo, hi = math.inf, -math.inf
        for arc in self.arcs():
            centre, radius, start = self._circle(arc)
            ends = [math.sin(start), math.sin(start + arc[2])]
            top = 1.0 if into_range(math.pi / 2, start, start + arc[2]) is not None else max(ends)
            below = into_range(-math.pi / 2, start, start + arc[2]) is not None
            bottom = -1.0 if below else min(ends)
            hi = max(hi, float(centre[1]) + radius * top)
            lo = min(lo, float(centre[1]) + radius * bottom)
        return lo, hi

    def at_height(self, w: float, count: int) -> tuple[np.ndarray, np.ndarray]:
        """Configurations with the tool at height w: (q (K, 2), u (K,)), the first joint sampled.

        For each of `count` values of q1 over its range the second joint's two solutions of
        w = |l1| sin(q1 + phi1) + |l2| sin(q1 + q2 + phi2) within its limits.
        """
        L1, L2 = float(np.linalg.norm(self.l1)), float(np.linalg.norm(self.l2))
        phi1, phi2 = math.atan2(self.l1[1], self.l1[0]), math.atan2(self.l2[1], self.l2[0])
        q1 = np.linspace(self.lower[0], self.upper[0], count)
        s = (w - L1 * np.sin(q1 + phi1)) / L2
        ok = np.abs(s) <= 1.0
        q1, s = q1[ok], s[ok]
        gammas = (np.arcsin(s), math.pi - np.arcsin(s))
        qs, us = [], []
        for gamma in gammas:
            q2 = gamma - q1 - phi2
            lo2, hi2 = self.lower[1], self.upper[1]
            k = np.ceil((lo2 - q2) / TWO_PI - 1e-12)
            q2 = q2 + k * TWO_PI
            keep = q2 <= hi2 + 1e-12
            qs.append(np.stack([q1[keep], q2[keep]], axis=1))
            us.append(L1 * np.cos(q1[keep] + phi1) + L2 * np.cos(gamma[keep]))
        return np.concatenate(qs), np.concatenate(us)


def planar_arm(planned: PlanRobot, joints: Sequence[str]) -> PlanarArm | None:
    """The closed form of `joints` (the arm, root to tool) if they make a planar-reach arm.

    `planned.robot`'s root frame is the base; evaluated with every joint at zero (the closed form's
    reference, not the rest pose). None unless there are exactly two revolute joints with
    parallel horizontal axes.
    """
    import pinocchio as pin

    robot = planned.robot
    model = robot.model
    if len(joints) != 2 or not all(model.existJointName(j) for j in joints):
        return None
    ids = [model.getJointId(j) for j in joints]
    if any(model.joints[i].nv != 1 or model.joints[i].nq != 1 for i in ids):
        return None
    q = robot.neutral()
    P3 = robot.tool_position(q)
    data = robot.data
    pin.computeJointJacobians(model, data, q)
    axes = []
    for i in ids:
        J = np.asarray(pin.getJointJacobian(model, data, i, pin.WORLD))
        col = J[:, model.joints[i].idx_v]
        if np.linalg.norm(col[3:]) < 0.5:  # a prismatic joint: no rotation
            return None
        axes.append(col[3:] / np.linalg.norm(col[3:]))
    a = axes[0]
    if np.linalg.norm(np.cross(a, axes[1])) > PARALLEL_TOL or abs(a[2]) > PARALLEL_TOL:
        return None
    if a @ axes[1] < 0:  # antiparallel: the second joint turns the other way
        return None
    # copies: `data` is the robot's, and a view into it would move with the next user's call
    S = np.array(data.oMi[ids[0]].translation, dtype=float)
    P2 = np.array(data.oMi[ids[1]].translation, dtype=float)
    z = np.array([0.0, 0.0, 1.0])
    e_u = np.cross(z, a)

    def in_plane(v: np.ndarray) -> np.ndarray:
        return np.array([float(v @ e_u), float(v @ z)])

    return PlanarArm(
        joints=(joints[0], joints[1]),
        shoulder=S,
        axis=a,
        e_u=e_u,
        offset=float((P3 - S) @ a),
        l1=in_plane(P2 - S),
        l2=in_plane(P3 - P2),
        planned=planned,
    )
