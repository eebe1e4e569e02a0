"""The simulator's step loop: PD motor, implicit damping, friction and joint stops.

One step (semi-implicit Euler, the default) at state (q, v) and reference (q_ref, v_ref):

1. motor torque tau = Kp (q_ref - q) + Kd (v_ref - v) [+ g(q)], saturated at the effort limit;
2. velocity-proportional torques (Kd of unsaturated joints, viscous damping D) are implicit:
   (M + dt B)(v* - v)/dt = tau_explicit - B v - nle, with B = diag(Kd + D). ABA adds
   `model.armature` to the diagonal of M, so armature = dt B gives exactly this, and the
   step is stable for any non-negative Kd and D;
3. Coulomb friction and joint stops are solved at velocity level, like MuJoCo's
   frictionloss and limit constraints: v' = argmin ½|v - v*|²_(M+dtB) + dt Σ F_i |v_i|
   subject to the stop bounds, by projected Gauss-Seidel. A joint at rest with a small
   torque stays exactly at rest (no chatter), and since v = 0 is feasible the projection
   never adds kinetic energy;
4. q' = q + dt v', clamped to the limits against round-off.

RK4 integrates the smooth part (PD, gravity, damping) with the classic four stages, then
applies the same projection. `native.py` runs the identical algorithm in C++; the Python
loop here is the reference and the fallback.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

# Pinocchio joint model -> the joint code both engines use (revolute 0-3, prismatic 4-7).
JOINT_TYPES = {
    "JointModelRX": 0,
    "JointModelRY": 1,
    "JointModelRZ": 2,
    "JointModelRevoluteUnaligned": 3,
    "JointModelPX": 4,
    "JointModelPY": 5,
    "JointModelPZ": 6,
    "JointModelPrismaticUnaligned": 7,
}

PARAM_FIELDS = ("kp", "kd", "damping", "friction", "lower", "upper", "effort", "vabort")
KP, KD, DAMPING, FRICTION, LOWER, UPPER, EFFORT, VABORT = range(len(PARAM_FIELDS))
FAIL_NONE, FAIL_NONFINITE, FAIL_VELOCITY, FAIL_ENERGY = range(4)
FLAG_SATURATED = 1
FLAG_STOP = 2
PGS_MAX_ITERS = 200
PGS_TOL = 1e-14
ENERGY_EVERY = 100  # steps between kinetic-energy checks


@dataclass(frozen=True)
class Plant:
    """Everything a rollout needs besides the initial state and the reference."""

    model: Any  # pinocchio.Model, only nq == nv one-dof joints
    params: np.ndarray  # (n, len(PARAM_FIELDS))
    gravity_comp: bool
    dt: float  # [s]
    integrator: str  # "euler" | "rk4"
    energy_max: float  # [J] kinetic energy treated as a blow-up


@dataclass(frozen=True)
class Rollout:
    """States at every step; a failed run stops at `fail_step` (rows after it are unset)."""

    q: np.ndarray  # (steps + 1, n) [rad or m]
    v: np.ndarray  # (steps + 1, n)
    tau: np.ndarray  # (steps, n) motor torque applied during each step [N·m or N]
    flags: np.ndarray  # (steps, n) uint8: FLAG_SATURATED | FLAG_STOP
    fail_step: int  # -1 when the run completed
    fail_joint: int  # index, -1 when not joint-specific
    fail_code: int


class _Stepper:
    """The Python reference step; mirrors `_native/rollout.cpp` line by line."""

    def __init__(self, plant: Plant) -> None:
        import pinocchio as pin

        self.pin = pin
        self.model = plant.model.copy()
        self.model.armature = np.zeros(self.model.nv)  # URDF has no rotor inertia; C++ too
        self.data = self.model.createData()
        self.p = plant.params
        self.n = self.model.nv
        self.dt = plant.dt
        self.gc = plant.gravity_comp
        self.sat = np.zeros(self.n, dtype=bool)
        self.lo = np.full(self.n, -np.inf)
        self.hi = np.full(self.n, np.inf)
        self.vstar = np.zeros(self.n)

    def motor(self, q: np.ndarray, v: np.ndarray, qr: np.ndarray, vr: np.ndarray) -> np.ndarray:
        p = self.p
        t = p[:, KP] * (qr - q) + p[:, KD] * (vr - v)
        if self.gc:
            t = t + self.pin.computeGeneralizedGravity(self.model, self.data, q)
        self.sat = np.abs(t) > p[:, EFFORT]
        out: np.ndarray = np.where(self.sat, np.copysign(p[:, EFFORT], t), t)
        return out

    def project(
        self, q: np.ndarray, vs: np.ndarray, qp: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        p, dt, n = self.p, self.dt, self.n
        self.hi = np.where(qp > p[:, UPPER], vs + (p[:, UPPER] - qp) / dt, np.inf)
        self.lo = np.where(qp < p[:, LOWER], vs + (p[:, LOWER] - qp) / dt, -np.inf)
        if not (
            np.any(p[:, FRICTION] > 0) or np.isfinite(self.hi).any() or np.isfinite(self.lo).any()
        ):
            return vs.copy(), qp.copy()
        A = self.pin.computeMinverse(self.model, self.data, q)
        Al = A.tolist()
        for i in range(n):  # only the upper triangle is guaranteed
            for j in range(i):
                Al[i][j] = Al[j][i]
        vl, lo, hi, fr = vs.tolist(), self.lo.tolist(), self.hi.tolist(), p[:, FRICTION].tolist()
        lam = [0.0] * n
        for _ in range(PGS_MAX_ITERS):
            change = scale = 0.0
            for i in range(n):
                Ai = Al[i]
                w = vl[i]
                for j in range(n):
                    w += Ai[j] * lam[j]
                w -= Ai[i] * lam[i]
                thr = Ai[i] * dt * fr[i]
                u = w - thr if w > thr else (w + thr if w < -thr else 0.0)
                u = min(max(u, lo[i]), hi[i])
                li = (u - w) / Ai[i]
                change = max(change, abs(li - lam[i]))
                lam[i] = li
                scale = max(scale, abs(li))
            if change <= PGS_TOL * (1.0 + scale):
                break
        dv = np.array([_dot(Al[i], lam) for i in range(n)])
        return vs + dv, qp + dt * dv

    def clamp(self, q: np.ndarray) -> np.ndarray:
        out: np.ndarray = np.minimum(np.maximum(q, self.p[:, LOWER]), self.p[:, UPPER])
        return out

    def euler(self, q: np.ndarray, v: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, ...]:
        p, dt, n = self.p, self.dt, self.n
        tau_pd = self.motor(q, v, r[:n], r[n:])
        b = p[:, DAMPING] + np.where(self.sat, 0.0, p[:, KD])
        self.model.armature = dt * b
        a = self.pin.aba(self.model, self.data, q, v, tau_pd - p[:, DAMPING] * v)
        self.vstar = v + dt * a
        vn, qn = self.project(q, self.vstar, q + dt * self.vstar)
        qn = self.clamp(qn)
        tau = np.where(self.sat, tau_pd, tau_pd - p[:, KD] * (vn - v))
        return qn, vn, tau

    def accel(self, q: np.ndarray, v: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = self.n
        tau = self.motor(q, v, r[:n], r[n:])
        a = self.pin.aba(self.model, self.data, q, v, tau - self.p[:, DAMPING] * v).copy()
        return a, tau

    def rk4(self, q: np.ndarray, v: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, ...]:
        """r: three reference rows at t, t + dt/2, t + dt."""
        dt = self.dt
        k1v, tau = self.accel(q, v, r[0])
        sat1 = self.sat
        k1q = v
        k2q = v + 0.5 * dt * k1v
        k2v, _ = self.accel(q + 0.5 * dt * k1q, k2q, r[1])
        k3q = v + 0.5 * dt * k2v
        k3v, _ = self.accel(q + 0.5 * dt * k2q, k3q, r[1])
        k4q = v + dt * k3v
        k4v, _ = self.accel(q + dt * k3q, k4q, r[2])
        self.vstar = v + (dt / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
        qpred = q + (dt / 6.0) * (k1q + 2.0 * k2q + 2.0 * k3q + k4q)
        self.sat = sat1
        vn, qn = self.project(q, self.vstar, qpred)
        return self.clamp(qn), vn, tau


def rollout_python(plant: Plant, q0: np.ndarray, v0: np.ndarray, ref: np.ndarray) -> Rollout:
    """Reference implementation of the rollout; the compiled `_native` one does the same.

    `ref` rows are [q_ref, v_ref] at t = k dt (Euler, steps + 1 rows) or k dt/2 (RK4,
    2 steps + 1 rows).
    """
    s = _Stepper(plant)
    n = s.n
    steps = (ref.shape[0] - 1) // (2 if plant.integrator == "rk4" else 1)
    Q = np.full((steps + 1, n), np.nan)
    V = np.full((steps + 1, n), np.nan)
    T = np.full((steps, n), np.nan)
    F = np.zeros((steps, n), dtype=np.uint8)
    q, v = np.array(q0, dtype=float), np.array(v0, dtype=float)
    Q[0], V[0] = q, v
    vabort = plant.params[:, VABORT]
    for k in range(steps):
        if plant.integrator == "rk4":
            q, v, T[k] = s.rk4(q, v, ref[2 * k : 2 * k + 3])
        else:
            q, v, T[k] = s.euler(q, v, ref[k])
        F[k] = s.sat * FLAG_SATURATED | (np.isfinite(s.lo) | np.isfinite(s.hi)) * FLAG_STOP
        Q[k + 1], V[k + 1] = q, v
        code, joint = _check(q, v, vabort)
        if code == FAIL_NONE and (k + 1) % ENERGY_EVERY == 0:
            s.model.armature = np.zeros(n)
            ke = s.pin.computeKineticEnergy(s.model, s.data, q, v)
            if not ke <= plant.energy_max:
                code = FAIL_ENERGY
        if code != FAIL_NONE:
            return Rollout(Q, V, T, F, k + 1, joint, code)
    return Rollout(Q, V, T, F, -1, -1, FAIL_NONE)


def _check(q: np.ndarray, v: np.ndarray, vabort: np.ndarray) -> tuple[int, int]:
    for i in range(q.shape[0]):
        if not (np.isfinite(q[i]) and np.isfinite(v[i])):
            return FAIL_NONFINITE, i
        if abs(v[i]) > vabort[i]:
            return FAIL_VELOCITY, i
    return FAIL_NONE, -1


def _dot(a: list[float], b: list[float]) -> float:
    """Left-to-right sum, the same rounding as the C++ loop."""
    out = 0.0
    for x, y in zip(a, b, strict=True):
        out += x * y
    return out
