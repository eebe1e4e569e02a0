"""The Python engine's Euler loop for the common case, written for the interpreter.

Why a separate loop: in a per-step Python loop around a sub-microsecond ABA call, the cost
is the interpreter's: function calls, attribute lookups, temporary lists. Most steps of
a tracking run have no saturated joint, no joint near a stop and (on joints without
Coulomb friction) nothing for the constraint solver to do; for those this loop computes
exactly the operations of `Stepper.euler` (the same expressions in the same order, so
the same bits as the compiled engine) inline, with every name a local. Any step that
needs more (saturation, a stop, a non-finite state) is run by `Stepper.euler` instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from operator import gt, lt
from typing import Any, cast

from armcli.sim.stepper import (
    ENERGY_EVERY,
    FAIL_ENERGY,
    FAIL_NONE,
    FAIL_NONFINITE,
    FAIL_VELOCITY,
    FLAG_SATURATED,
    FLAG_STOP,
    Stepper,
    pgs,
)


@dataclass
class Record:
    """Flat per-step outputs (one numpy conversion at the end) and the outcome."""

    q: list[float]
    v: list[float]
    tau: list[float]
    flagged: list[tuple[int, list[int]]]  # (step, flags) of the steps with a flag set
    fail_step: int = -1
    fail_joint: int = -1
    fail_code: int = FAIL_NONE


def check(q: list[float], v: list[float], vabort: list[float]) -> tuple[int, int]:
    """The state check of both engines, in joint order: non-finite, then too fast."""
    for i in range(len(q)):
        if not (math.isfinite(q[i]) and math.isfinite(v[i])):
            return FAIL_NONFINITE, i
        if abs(v[i]) > vabort[i]:
            return FAIL_VELOCITY, i
    return FAIL_NONE, -1


def flags_of(s: Stepper) -> list[int] | None:
    """The step's per-joint flags, None when none is set (the common case)."""
    if True in s.sat or True in s.stop:
        return [FLAG_SATURATED * a | FLAG_STOP * b for a, b in zip(s.sat, s.stop, strict=True)]
    return None


def finish(rec: Record, s: Stepper, k: int, q: list[float], v: list[float], emax: float) -> bool:
    """Record the outcome of the checks after step k; True when the run failed there.

    The state check, and every ENERGY_EVERY steps the kinetic energy.
    """
    code = FAIL_NONE
    # sum |v| <= min vabort: every |v_i| is finite and within its limit, and q, moved by
    # dt v from a finite state, is finite; otherwise run the exact check
    if not (sum(map(abs, v)) <= s.vmin and math.isfinite(sum(q))):
        code, rec.fail_joint = check(q, v, s.vabort)
    if code == FAIL_NONE and (k + 1) % ENERGY_EVERY == 0:
        s.set_armature(None)  # the kinetic energy of the arm alone
        s.setq(q)
        s.va[:] = v
        if not s.pin.computeKineticEnergy(s.model, s.data, s.qa, s.va) <= emax:
            code = FAIL_ENERGY
    if code != FAIL_NONE:
        rec.fail_step, rec.fail_code = k + 1, code
    return code != FAIL_NONE


def euler_loop(
    s: Stepper, q: list[float], v: list[float], Rq: list[Any], Rv: list[Any], energy_max: float
) -> Record:
    """Semi-implicit Euler over the reference rows Rq, Rv (one per step)."""
    kp, kd, d, effort, dt, lower, upper = s.kp, s.kd, s.damp, s.effort, s.dt, s.lower, s.upper
    qa, va, ta, aba, gravity = s.qa, s.va, s.ta, s.pin.aba, s.pin.computeGeneralizedGravity
    buf, pack3 = cast(Any, s.buf), s.pack3  # a numpy array is a writable buffer
    model, data, gc, nosat, vmin = s.model, s.data, s.gc, [False] * s.n, s.vmin
    armed, isfinite, friction, minverse = (
        False,
        math.isfinite,
        s.any_friction,
        s.pin.computeMinverse,
    )
    free_lo, free_hi, fdt, n = [-math.inf] * s.n, [math.inf] * s.n, [dt * f for f in s.fric], s.n
    rec = Record(list(q), list(v), [], [])
    Qx, Vx, Tx = rec.q.extend, rec.v.extend, rec.tau.extend
    setq, fast = (
        s.setq,
        True not in s.unbounded,
    )  # continuous joints: every step through Stepper.euler
    for k, (qr, vr) in enumerate(zip(Rq, Rv, strict=True)):
        done = False
        t = [a * (b - c) + e * (f - g) for a, b, c, e, f, g in zip(kp, qr, q, kd, vr, v)]  # noqa: B905
        if gc:
            setq(q)
            t = [x + y for x, y in zip(t, gravity(model, data, qa).tolist())]  # noqa: B905
        if fast and not any(map(gt, map(abs, t), effort)):
            if not armed:
                s.set_armature(nosat)
                armed = True
            pack3(buf, 0, *q, *v, *[x - c * y for x, c, y in zip(t, d, v)])  # noqa: B905
            a = aba(model, data, qa, va, ta).tolist()
            vs = [x + dt * y for x, y in zip(v, a)]  # noqa: B905
            qp = [x + dt * y for x, y in zip(q, vs)]  # noqa: B905
            if not (any(map(gt, qp, upper)) or any(map(lt, qp, lower))):
                if friction:  # Stepper.project without stops: friction alone
                    A = minverse(model, data, qa).tolist()
                    for i in range(n):  # only the upper triangle is guaranteed
                        for j in range(i):
                            A[i][j] = A[j][i]
                    dv = pgs(A, vs, free_lo, free_hi, fdt, s.lam)
                    qp = [x + dt * y for x, y in zip(qp, dv)]  # noqa: B905
                    qp = [min(max(x, lo), hi) for x, lo, hi in zip(qp, lower, upper)]  # noqa: B905
                    vs = [x + y for x, y in zip(vs, dv)]  # noqa: B905
                tau = [x - c * (y - z) for x, c, y, z in zip(t, kd, vs, v)]  # noqa: B905
                if not any(map(gt, map(abs, tau), effort)):
                    q, v, done = qp, vs, True  # within the limits: the clamp is a no-op
                    Tx(tau)
        if not done:
            q, v = s.euler(q, v, qr, vr)
            armed = False
            Tx(s.tau)
            flags = flags_of(s)
            if flags is not None:
                rec.flagged.append((k, flags))
        Qx(q)
        Vx(v)
        if (k + 1) % ENERGY_EVERY == 0 or not (sum(map(abs, v)) <= vmin and isfinite(sum(q))):
            armed = False  # finish() may reset the armature
            if finish(rec, s, k, q, v, energy_max):
                break
    return rec


def rk4_loop(s: Stepper, q: list[float], v: list[float], R: list[Any], energy_max: float) -> Record:
    """Classic RK4 over the reference rows R (three per step); every step is general."""
    rec = Record(list(q), list(v), [], [])
    for k in range(len(R) // 3):
        q, v = s.rk4(q, v, R[3 * k], R[3 * k + 1], R[3 * k + 2])
        rec.tau.extend(s.tau)
        flags = flags_of(s)
        if flags is not None:
            rec.flagged.append((k, flags))
        rec.q.extend(q)
        rec.v.extend(v)
        if finish(rec, s, k, q, v, energy_max):
            break
    return rec
