"""One stability verdict per PD loop, its one remedy, and its wording.

Two loops close the same gains: armcli's simulator (semi-implicit Euler, damping
implicit; RK4 with `--integrator rk4`) and an explicit torque loop such as a ros2_control
effort controller in Gazebo (damping explicit). Each verdict names its loop, says what is
too stiff, and offers one remedy computed by `suggest`: a time step, or the gains scaled
into the stable range. `check` reports these verdicts; `simulate` refuses with the same
verdict and remedy (`refuse_unstable`), so the two commands cannot disagree. The
explicit loop's stability implies the implicit one's (A_implicit = A_explicit + 4 dt D),
so gains that pass the explicit loop pass both.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from armcli.analysis import pdloop
from armcli.analysis import stability as stab
from armcli.analysis.pdloop import PD, Linearised, Scaled, Scheme
from armcli.errors import UnstableLoopError

# Remedies: a time step or gains this fraction inside the strict bound, rounded down to
# REMEDY_DIGITS significant digits (a rounded remedy stays stable: A grows as dt or a gain
# shrinks).
STABLE_MARGIN = 0.9
REMEDY_DIGITS = 2
LIST_GAINS = 4  # a remedy names each joint's gains up to this many joints

LOOP_NAMES: dict[str, str] = {
    "implicit": "armcli simulate (damping implicit)",
    "explicit": "explicit torque loop (a torque controller updated every dt, e.g. in Gazebo)",
    "rk4": "armcli simulate --integrator rk4",
}


@dataclass(frozen=True)
class Suggestion:
    """A remedy that makes a loop stable: either the time step, or the gains at the given dt."""

    dt: float  # [s] STABLE_MARGIN inside dt_max, rounded down
    kp: tuple[float, ...] | None  # per controlled joint; None: no gain scale helps at dt
    kd: tuple[float, ...] | None
    kp_factor: float | None  # the factor applied to Kp before rounding (1.0: kept; None: none)
    kd_factor: float | None  # the same for Kd


@dataclass(frozen=True)
class LoopVerdict:
    """One loop's verdict over the operating points, with its bounds and remedy."""

    scheme: Scheme
    loop: str  # which loop this is, in words (LOOP_NAMES)
    stable: bool
    a: float  # Kp dt² lambda at the worst point (largest gains; the scalar explanation)
    b: float  # D dt lambda
    spectral_radius: float  # of the linearised step at the worst point
    dt_max: float  # largest stable dt with these gains [s] (inf: every dt)
    gain_scale: float | None  # largest stable factor on `scaled` at dt (None: none helps)
    scaled: Scaled | None  # which gains that factor scales
    suggestion: Suggestion | None  # None when stable
    worst: int  # index of the operating point that sets dt_max


@dataclass(frozen=True)
class StabilityReport:
    """Both Euler loops at `dt` over the operating points (what `check` reports)."""

    dt: float  # [s]
    lambda_max: float  # max over samples of lambda_max(M^-1) on the controlled joints
    q_worst: tuple[float, ...]  # controlled joints at the worst sample [rad or m]
    kp: float  # largest Kp [N·m/rad]
    d: float  # largest Kd + damping [N·m·s/rad]
    gravity_stiffness: float  # largest eigenvalue of dg/dq over the samples, >= 0 [N·m/rad]
    explicit: LoopVerdict
    implicit: LoopVerdict
    kd_max_explicit: float | None  # largest common Kd stable explicitly at dt (None: none)
    kp_max_implicit: float | None  # largest Kp (x gain_scale) stable implicitly (None: none)


def round_down(x: float, digits: int = REMEDY_DIGITS) -> float:
    """X rounded down to `digits` significant digits (a dt or gain still below a bound)."""
    if x <= 0 or not np.isfinite(x):
        return x
    step = 10.0 ** (np.floor(np.log10(x)) - digits + 1)
    return float(f"{np.floor(x / step + 1e-9) * step:.{digits}g}")


def suggest(dt_max: float, scale: stab.GainScale | None, pd: PD) -> Suggestion:
    """The one remedy: dt, or the gains scaled, STABLE_MARGIN inside their bound.

    Both are rounded down, so the rounded values stay stable.
    """
    dt = round_down(STABLE_MARGIN * dt_max)
    if scale is None or scale.factor <= 0.0:
        return Suggestion(dt, None, None, None, None)
    f = STABLE_MARGIN * min(scale.factor, 1.0)
    f_kp, f_kd = (f if scale.kp else 1.0), (f if scale.kd else 1.0)
    kp = tuple(round_down(f_kp * float(x)) if scale.kp else float(x) for x in pd.kp)
    kd = tuple(round_down(f_kd * float(x)) if scale.kd else float(x) for x in pd.kd)
    return Suggestion(dt, kp, kd, f_kp, f_kd)


def verdict(lin: Linearised, pd: PD, dt: float, scheme: Scheme) -> LoopVerdict:
    """One loop's verdict at dt over every operating point, its bounds and its remedy."""
    with pdloop.one_blas_thread():
        dt_max, worst = stab.dt_max_at(lin, pd, scheme, dt)
        ok = stab.stable(lin, pd, dt, scheme)
        scale = stab.gain_scale(lin, pd, dt, scheme)
        lam = _lambda_max(lin.M[worst], pd)
        step = stab.step_matrix(lin.M[worst], lin.G[worst], pd, dt, scheme)
        radius = stab.spectral_radius(step)
    kp, d = _largest(pd.kp), _largest(pd.kd + pd.damping)
    return LoopVerdict(
        scheme,
        LOOP_NAMES[scheme],
        ok,
        kp * dt * dt * lam,
        d * dt * lam,
        radius,
        dt_max,
        None if scale is None else scale.factor,
        None if scale is None else scale.label,
        None if ok else suggest(dt_max, scale, pd),
        worst,
    )


def analyse(
    lin: Linearised, q_samples: Sequence[Sequence[float]], pd: PD, dt: float
) -> StabilityReport:
    """Both Euler loops at dt over the operating points (what `check` reports)."""
    explicit = verdict(lin, pd, dt, "explicit")
    implicit = verdict(lin, pd, dt, "implicit")
    shown = implicit if not implicit.stable or explicit.stable else explicit
    kp = _largest(pd.kp)
    with pdloop.one_blas_thread():
        lam = max(_lambda_max(M, pd) for M in lin.M)
        g = max(0.0, float(np.max(np.linalg.eigvalsh(lin.G)[:, -1]))) if len(lin) else 0.0
        kd_max = _common_kd_max(lin, pd, dt)
    return StabilityReport(
        dt=dt,
        lambda_max=lam,
        q_worst=tuple(float(x) for x in q_samples[shown.worst]),
        kp=kp,
        d=_largest(pd.kd + pd.damping),
        gravity_stiffness=g,
        explicit=explicit,
        implicit=implicit,
        kd_max_explicit=kd_max,
        kp_max_implicit=None if implicit.gain_scale is None else implicit.gain_scale * kp,
    )


def cause(v: LoopVerdict, kp: float, d: float, gravity: float, lam: float) -> str:
    """What is too stiff for the inertia, in the loop's terms."""
    grav = f", gravity's stiffness up to {gravity:.3g} N·m/rad" if gravity > 0 else ""
    gains = (
        f"Kp up to {kp:g}"
        if v.scheme == "implicit"
        else f"Kp up to {kp:g}, Kd + damping up to {d:g}"
    )
    return f"{gains}{grav} too stiff for lambda_max(M^-1) = {lam:.4g}"


def remedy(s: Suggestion, names: Sequence[str], dt: float) -> str:
    """The suggestion in words: a dt, or the gains scaled at this dt."""
    text = f"e.g. dt = {s.dt:g} s"
    if s.kp is None or s.kd is None or s.kp_factor is None:
        return text + " (at this dt no lower gains are stable)"
    scaled = [g for g, f in (("Kp", s.kp_factor), ("Kd", s.kd_factor)) if f != 1.0]
    factor = s.kp_factor if s.kp_factor != 1.0 else s.kd_factor
    text += f", or keep dt = {dt:g} s with {' and '.join(scaled)} x {factor:.3g}"
    if len(names) <= LIST_GAINS:
        each = (f"{n} kp {p:g} kd {d:g}" for n, p, d in zip(names, s.kp, s.kd, strict=True))
        text += " (" + ", ".join(each) + ")"
    return text


def message(
    v: LoopVerdict,
    names: Sequence[str],
    q: Sequence[float],
    dt: float,
    numbers: tuple[float, float, float, float],
) -> str:
    """The whole sentence for an unstable loop: which loop, why, where, the edge, a remedy.

    `numbers` = (largest Kp, largest Kd + damping, gravity's stiffness, lambda_max).
    """
    where = ", ".join(f"{n} = {x:.3g}" for n, x in zip(names, q, strict=True))
    edge = "any dt" if math.isinf(v.dt_max) else f"dt <= {v.dt_max:.3g} s"
    text = (
        f"{v.loop} diverges at dt = {dt:g} s: {cause(v, *numbers)} at {where} "
        f"(step spectral radius {v.spectral_radius:.3g} > 1); stable for {edge}"
    )
    return text if v.suggestion is None else f"{text}; {remedy(v.suggestion, names, dt)}"


def refuse_unstable(
    lin: Linearised,
    pd: PD,
    dt: float,
    scheme: Scheme,
    names: Sequence[str],
    qs: Sequence[Sequence[float]],
) -> None:
    """Raise UnstableLoopError, with the verdict's remedy, when the loop diverges at dt."""
    with pdloop.one_blas_thread():
        if stab.stable(lin, pd, dt, scheme):
            return
        euler_ok = scheme == "rk4" and stab.stable(lin, pd, dt, "implicit")
    v = verdict(lin, pd, dt, scheme)
    g = max(0.0, _top(lin.G[v.worst]))
    numbers = (_largest(pd.kp), _largest(pd.kd + pd.damping), g, _lambda_max(lin.M[v.worst], pd))
    text = message(v, names, qs[v.worst], dt, numbers)
    if euler_ok:
        text += f"; or the default euler integrator: {LOOP_NAMES['implicit']} is stable here"
    s = v.suggestion
    assert s is not None  # an unstable verdict always carries one
    raise UnstableLoopError(text, scheme=scheme, dt=dt, suggestion_dt=s.dt, kp=s.kp, kd=s.kd)


def _largest(x: np.ndarray) -> float:
    return float(np.max(x)) if x.size else 0.0


def _top(S: np.ndarray) -> float:
    """The largest eigenvalue of a symmetric matrix."""
    return float(np.linalg.eigvalsh(S)[-1]) if S.size else 0.0


def _lambda_max(M: np.ndarray, pd: PD) -> float:
    """lambda_max of the controlled block of M^-1 [1/(kg·m²)]."""
    idx = list(pd.idx)
    if not idx:
        return 0.0
    if len(idx) == M.shape[0]:  # every joint controlled: 1 / lambda_min(M), no inverse
        return 1.0 / float(np.linalg.eigvalsh(M)[0])
    Minv = np.linalg.inv(M)[np.ix_(idx, idx)]
    return _top(0.5 * (Minv + Minv.T))


def _common_kd_max(lin: Linearised, pd: PD, dt: float) -> float | None:
    """Largest Kd, the same on every controlled joint, stable explicitly at dt (None: none)."""
    base = PD(pd.idx, pd.kp, np.zeros_like(pd.kd), pd.damping)
    return stab.largest_along(lin, base, np.full(len(pd.idx), 2.0 * dt), dt, "explicit")
