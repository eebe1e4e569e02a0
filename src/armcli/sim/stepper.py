"""One simulator step in plain Python floats: the reference for `_native/rollout.cpp`.

Why plain floats: for an arm of a few joints, numpy's per-call overhead (~1 µs per
operation) dwarfs the arithmetic, while Pinocchio's ABA itself costs under a microsecond.
So the state lives in Python lists, Pinocchio is called on preallocated arrays, the
armature (implicit gains) is set only when the saturated set changes, and the constraint
solve runs only on steps where friction or a joint stop is involved.

Every floating-point operation is written in the same order as in the C++ file, so the
two engines agree to round-off (the tests require 1e-12; in practice they are equal).
"""

from __future__ import annotations

import math
import struct
from typing import Any

import numpy as np

PARAM_FIELDS = ("kp", "kd", "damping", "friction", "lower", "upper", "effort", "vabort")
KP, KD, DAMPING, FRICTION, LOWER, UPPER, EFFORT, VABORT = range(len(PARAM_FIELDS))
FAIL_NONE, FAIL_NONFINITE, FAIL_VELOCITY, FAIL_ENERGY = range(4)
FLAG_SATURATED = 1
FLAG_STOP = 2
ENERGY_EVERY = 100  # steps between kinetic-energy checks
PGS_MAX_ITERS = 200
PGS_TOL = 1e-14
INF = math.inf
REST_POS = 1e-12  # relative: a joint this close to a stop is on it (the projection's round-off)
REST_VEL = 1e-9  # [rad/s or m/s] and not moving away faster than this: resting on it


class Stepper:
    """Semi-implicit Euler or RK4 step with saturation, friction and joint stops.

    After each step: `sat` (saturated joints), `stop` (joints whose stop constraint was
    active) and `tau` (the motor torque applied during the step) describe it.
    """

    def __init__(self, model: Any, params: np.ndarray, gravity_comp: bool, dt: float) -> None:
        import pinocchio as pin

        self.pin = pin
        self.model = model.copy()
        self.data = self.model.createData()
        self.n = n = self.model.nv
        cols = np.asarray(params, dtype=float).T.tolist()
        self.kp, self.kd, self.damp, self.fric = cols[KP], cols[KD], cols[DAMPING], cols[FRICTION]
        self.lower, self.upper, self.effort, self.vabort = cols[LOWER:]
        self.vmin = min(self.vabort)
        self.any_friction = any(f > 0.0 for f in self.fric)
        self.gc = gravity_comp
        self.dt = dt
        nq = self.model.nq
        # continuous joints: Pinocchio's configuration holds (cos, sin) of their angle
        self.unbounded = [self.model.nqs[j] == 2 for j in range(1, self.model.njoints)]
        self.iq = [self.model.idx_qs[j] for j in range(1, self.model.njoints)]
        self.buf = np.zeros(nq + 2 * n)  # q, v, tau for Pinocchio, filled by one struct pack
        self.qa, self.va, self.ta = self.buf[:nq], self.buf[nq : nq + n], self.buf[nq + n :]
        self.pack3 = struct.Struct(f"{nq + 2 * n}d").pack_into
        self.sat = [False] * n
        self.lam = [0.0] * n  # the last PGS impulses: the next solve starts from them
        self.locked: list[int] = []  # RK4: joints held by their stops during the stages
        self.force: list[float] = []  # their stop forces (M⁻¹ units), for the sign test
        self.stop = [False] * n
        self.tau = [0.0] * n
        self._armature_key: tuple[bool, ...] | None = None  # () is the zero armature
        self._armature_sat: list[bool] | None = None
        self._no_stop = [False] * n
        self.set_armature(None)

    def set_armature(self, sat: list[bool] | None) -> None:
        """Implicit velocity gains of the Euler step: dt (D + Kd) on unsaturated joints.

        None: zero armature (RK4 and energy checks). Set only when it changes.
        """
        if sat is not None and sat == self._armature_sat:  # the per-step case: one compare
            return
        key = () if sat is None else tuple(sat)
        self._armature_sat = None if sat is None else list(sat)
        if key == self._armature_key:
            return
        if sat is None:
            self.model.armature = np.zeros(self.n)
        else:
            dt, d, kd = self.dt, self.damp, self.kd
            self.model.armature = np.array(
                [dt * (d[i] + (0.0 if sat[i] else kd[i])) for i in range(self.n)]
            )
        self._armature_key = key

    def setq(self, q: list[float]) -> None:
        """Pinocchio's configuration of the joint angles/positions q into `qa`."""
        if True not in self.unbounded:
            self.qa[:] = q
            return
        for i, x in enumerate(q):
            if self.unbounded[i]:
                self.qa[self.iq[i]], self.qa[self.iq[i] + 1] = math.cos(x), math.sin(x)
            else:
                self.qa[self.iq[i]] = x

    def _aba(self, q: list[float], v: list[float], tau: list[float]) -> list[float]:
        va, ta = self.va, self.ta
        self.setq(q)
        va[:], ta[:] = v, tau
        out: list[float] = self.pin.aba(self.model, self.data, self.qa, va, ta).tolist()
        return out

    def motor(
        self, q: list[float], v: list[float], qr: list[float], vr: list[float]
    ) -> list[float]:
        """PD(+gravity) torque before saturation."""
        t = [
            kp * (a - b) + kd * (c - d)
            for kp, a, b, kd, c, d in zip(self.kp, qr, q, self.kd, vr, v, strict=True)
        ]
        if self.gc:
            self.setq(q)
            g = self.pin.computeGeneralizedGravity(self.model, self.data, self.qa).tolist()
            t = [x + y for x, y in zip(t, g, strict=True)]
        return t

    def saturate(self, t: list[float]) -> list[float]:
        """Clamp the torques `t` at the effort limits; sets `sat`."""
        self.sat = sat = [abs(x) > e for x, e in zip(t, self.effort, strict=True)]
        if True not in sat:
            return t
        return [
            math.copysign(e, x) if s else x for x, e, s in zip(t, self.effort, sat, strict=True)
        ]

    def euler(
        self, q: list[float], v: list[float], qr: list[float], vr: list[float]
    ) -> tuple[list[float], list[float]]:
        """Semi-implicit Euler step, Kd and damping implicit.

        The motor torque of the whole step (explicit part + implicit Kd) respects the
        effort limit: a joint whose total would exceed it is saturated and the step solved
        again (at most n times).
        """
        n, dt, kd, d, e = self.n, self.dt, self.kd, self.damp, self.effort
        tau_pd = self.saturate(self.motor(q, v, qr, vr))
        while True:
            sat = self.sat
            self.set_armature(sat)
            a = self._aba(q, v, [t - c * x for t, c, x in zip(tau_pd, d, v, strict=True)])
            vs = [x + dt * y for x, y in zip(v, a, strict=True)]
            qp = [x + dt * y for x, y in zip(q, vs, strict=True)]
            qn, vn = self.project(q, vs, qp, 1.0)
            tau = [
                t if s else t - c * (y - x)
                for t, s, c, y, x in zip(tau_pd, sat, kd, vn, v, strict=True)
            ]
            over = [i for i in range(n) if not sat[i] and abs(tau[i]) > e[i]]
            if not over:
                break
            for i in over:
                self.sat[i] = True
                tau_pd[i] = math.copysign(e[i], tau[i])
        self.tau = tau
        return self.clamp(qn), vn

    def accel(
        self, q: list[float], v: list[float], qr: list[float], vr: list[float]
    ) -> list[float]:
        """Explicit acceleration under the saturated motor torque (RK4 stages).

        Joints in `self.locked` are held (zero acceleration) by their stops.
        """
        d = self.damp
        self.tau = tau = self.saturate(self.motor(q, v, qr, vr))
        a = self._aba(q, v, [tau[i] - d[i] * v[i] for i in range(self.n)])
        return self.hold(q, a) if self.locked else a

    def hold(self, q: list[float], a: list[float]) -> list[float]:
        """The acceleration with the locked joints' accelerations cancelled by stop forces.

        a + A[:, S] x with A[S, S] x = -a[S] (A = M⁻¹): exactly the constrained dynamics.
        """
        S = self.locked
        self.setq(q)
        A = self.pin.computeMinverse(self.model, self.data, self.qa).tolist()
        x = solve_spd([[A[min(i, j)][max(i, j)] for j in S] for i in S], [-a[i] for i in S])
        self.force = x
        out = []
        for i in range(self.n):
            acc = a[i]
            for jj, j in enumerate(S):
                acc += A[min(i, j)][max(i, j)] * x[jj]
            out.append(acc)
        for i in S:
            out[i] = 0.0
        return out

    def resting(self, q: list[float], v: list[float], r: list[float]) -> list[int]:
        """Joints resting on a stop and pressed into it; sets `locked`.

        At the stop (to round-off), not moving away, with the stop force pushing back: the
        set is found by dropping any joint whose force would pull it onto the stop.
        """
        n, lo, hi = self.n, self.lower, self.upper
        side = [
            1.0 if q[i] >= hi[i] - REST_POS * (1.0 + abs(hi[i])) and v[i] >= -REST_VEL
            else (-1.0 if q[i] <= lo[i] + REST_POS * (1.0 + abs(lo[i])) and v[i] <= REST_VEL
                  else 0.0)
            for i in range(n)
        ]  # fmt: skip
        if not any(side):
            return []
        self.locked = []
        a = self.accel(q, v, r[:n], r[n:])
        self.locked = [i for i in range(n) if side[i] * a[i] > 0.0]
        while self.locked:
            self.accel(q, v, r[:n], r[n:])
            keep = [i for k, i in enumerate(self.locked) if side[i] * self.force[k] <= 0.0]
            if len(keep) == len(self.locked):
                break
            self.locked = keep
        return self.locked

    def rk4(
        self, q: list[float], v: list[float], r0: list[float], r1: list[float], r2: list[float]
    ) -> tuple[list[float], list[float]]:
        """Classic RK4 step on the smooth dynamics, then the friction/stop projection.

        The reference rows r0, r1, r2 (at t, t + dt/2 and t + dt) come from one polynomial
        piece, so the stages see a smooth input.

        Joints resting on a stop are held by it through all four stages: integrating the
        free dynamics and projecting afterwards would leave a velocity of dt a / 2 on the
        stop and bias the stages' velocity-dependent torques on the joints coupled to it.
        """
        n, dt = self.n, self.dt
        h2, h6 = 0.5 * dt, dt / 6.0
        self.set_armature(None)
        locked = self.resting(q, v, r0)
        k1v = self.accel(q, v, r0[:n], r0[n:])
        sat1, tau1 = self.sat, self.tau  # stage-1 torque and flags are the ones reported
        k2q = [v[i] + h2 * k1v[i] for i in range(n)]
        k2v = self.accel([q[i] + h2 * v[i] for i in range(n)], k2q, r1[:n], r1[n:])
        k3q = [v[i] + h2 * k2v[i] for i in range(n)]
        k3v = self.accel([q[i] + h2 * k2q[i] for i in range(n)], k3q, r1[:n], r1[n:])
        k4q = [v[i] + dt * k3v[i] for i in range(n)]
        k4v = self.accel([q[i] + dt * k3q[i] for i in range(n)], k4q, r2[:n], r2[n:])
        vs = [v[i] + h6 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]) for i in range(n)]
        qp = [q[i] + h6 * (v[i] + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i]) for i in range(n)]
        self.sat, self.tau, self.locked = sat1, tau1, []
        qn, vn = self.project(q, vs, qp, 0.5)
        if locked:
            self.stop = list(self.stop)
            for i in locked:
                self.stop[i] = True
        return self.clamp(qn), vn

    def project(
        self, q: list[float], vs: list[float], qp: list[float], pos_gain: float
    ) -> tuple[list[float], list[float]]:
        """Friction and joint stops at velocity level (see `rollout.py`).

        A joint whose predicted position `qp` passes a stop gets the bound v' <= (upper -
        q)/dt (>= lower side alike) and the position q + dt v': it ends on the stop with no
        velocity into it. Other joints move by `pos_gain` dt dv: the whole impulse for
        Euler (q' = q + dt v'), half of it for RK4, whose positions already integrate the
        acceleration over the step (a constraint force constant over the step moves a
        joint by dt² Δa / 2 = dt dv / 2).
        """
        n, dt = self.n, self.dt
        if not self.any_friction and all(
            lo <= x <= hi for x, lo, hi in zip(qp, self.lower, self.upper, strict=True)
        ):  # the common step: nothing to solve
            self.stop = self._no_stop
            return qp, vs
        lo, hi = [-INF] * n, [INF] * n
        for i in range(n):
            if qp[i] > self.upper[i]:
                hi[i] = (self.upper[i] - q[i]) / dt
            elif qp[i] < self.lower[i]:
                lo[i] = (self.lower[i] - q[i]) / dt
        self.stop = [hi[i] < INF or lo[i] > -INF for i in range(n)]
        if not (self.any_friction or any(self.stop)):
            return qp, vs
        self.setq(q)
        A = self.pin.computeMinverse(self.model, self.data, self.qa).tolist()
        for i in range(n):  # only the upper triangle is guaranteed
            for j in range(i):
                A[i][j] = A[j][i]
        dv = pgs(A, vs, lo, hi, [dt * f for f in self.fric], self.lam)
        vn = [vs[i] + dv[i] for i in range(n)]
        qn = [
            q[i] + dt * vn[i] if self.stop[i] else qp[i] + pos_gain * dt * dv[i] for i in range(n)
        ]
        return qn, vn

    def clamp(self, q: list[float]) -> list[float]:
        """Positions clamped to the limits (against round-off)."""
        lo, hi = self.lower, self.upper
        return [min(max(q[i], lo[i]), hi[i]) for i in range(self.n)]


def pgs(
    A: list[list[float]],
    vs: list[float],
    lo: list[float],
    hi: list[float],
    fdt: list[float],
    lam: list[float],
) -> list[float]:
    """Velocity change of friction and stops, by projected Gauss-Seidel.

    dv = A lam minimises ½|v' - vs|²_(A⁻¹) + Σ fdt_i |v'_i| with lo <= v' <= hi; v' = 0 is
    feasible, so no energy is added. `lam` (updated in place) holds the previous solve's
    impulses: a warm start, so a sticking joint converges in one sweep instead of ~30.
    """
    n = len(vs)
    for _ in range(PGS_MAX_ITERS):
        change = scale = 0.0
        for i, (Ai, w, lo_i, hi_i, f) in enumerate(zip(A, vs, lo, hi, fdt, strict=True)):
            for a, x in zip(Ai, lam, strict=True):
                w += a * x
            Aii = Ai[i]
            w -= Aii * lam[i]
            thr = Aii * f
            u = w - thr if w > thr else (w + thr if w < -thr else 0.0)
            if u < lo_i:  # comparisons written out: the same results as min/max
                u = lo_i
            if u > hi_i:
                u = hi_i
            li = (u - w) / Aii
            d = abs(li - lam[i])
            if d > change:
                change = d
            lam[i] = li
            d = abs(li)
            if d > scale:
                scale = d
        if change <= PGS_TOL * (1.0 + scale):
            break
    out = []
    for i in range(n):
        s = 0.0
        for a, x in zip(A[i], lam, strict=True):
            s += a * x
        out.append(s)
    return out


def solve_spd(A: list[list[float]], b: list[float]) -> list[float]:
    """Solve A x = b for a small symmetric positive definite A.

    Cholesky, in the same operation order as the C++ engine.
    """
    n = len(b)
    L = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1):
            s = A[i][j]
            for k in range(j):
                s -= L[i][k] * L[j][k]
            L[i][j] = math.sqrt(s) if i == j else s / L[j][j]
    y = [0.0] * n
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i][k] * y[k]
        y[i] = s / L[i][i]
    x = [0.0] * n
    for i in reversed(range(n)):
        s = y[i]
        for k in range(i + 1, n):
            s -= L[k][i] * x[k]
        x[i] = s / L[i][i]
    return x
