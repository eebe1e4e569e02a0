"""A ros2_control controller's PD(+I) loop at its update rate: the verdict and its remedy.

The loop is the zero-order hold of `analysis.zoh` (gz_ros2_control holds the effort for
1/update_rate). The verdict gives the largest stable hold time, the rate that passes and
the gains that pass at the configured rate, each STABLE_MARGIN inside its bound and
rounded (a rate up, gains down) and checked again after rounding. `check` reports it
(`pd-rate-unstable`, for a spec's `control.controller_update_rate` and a controllers
YAML's `update_rate`); `ros-package` refuses to write a package whose controller diverges.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from armcli.analysis import pdloop, zoh
from armcli.analysis.pdloop import Linearised
from armcli.analysis.verdict import LIST_GAINS, STABLE_MARGIN, round_down
from armcli.analysis.zoh import Pid

GZ_PHYSICS_RATE = 1000  # [Hz] Gazebo's default physics step (1 ms), gz_ros2_control demos' rate
RATE_DIGITS = 2  # a suggested rate is rounded up to this many significant digits
RETRIES = 8  # a rounded remedy that is not stable is shrunk by STABLE_MARGIN this many times


@dataclass(frozen=True)
class Remedy:
    """What passes: a rate [Hz] (the gains kept) and gains at the configured rate."""

    rate: int | None  # None: no rate helps (the gains cannot be held by any hold time)
    factor: float | None  # Pid.scaled factor of the gains below; None: no lower gains help
    kp: tuple[float, ...] | None
    kd: tuple[float, ...] | None
    ki: tuple[float, ...] | None


@dataclass(frozen=True)
class RateVerdict:
    """The held loop at `rate` over the operating points, with its edge and remedy."""

    rate: float  # [Hz]
    stable: bool
    hold_max: float  # [s] the largest stable hold time (inf: any)
    radius: float  # the closed loop's spectral radius at the worst point, at this rate
    worst: int  # the index of the point that sets hold_max
    left_out: int  # points where Kp + gravity's stiffness is not >= 0 (the gains cannot hold)
    remedy: Remedy | None  # None when stable

    @property
    def hold(self) -> float:
        """The hold time 1/rate [s]."""
        return 1.0 / self.rate

    @property
    def rate_min(self) -> float:
        """The least stable rate 1/hold_max [Hz] (0: any rate; inf: none)."""
        return (
            0.0
            if math.isinf(self.hold_max)
            else (math.inf if self.hold_max <= 0 else 1.0 / self.hold_max)
        )


def rate_verdict(lin: Linearised, pid: Pid, rate: float) -> RateVerdict:
    """The held loop's verdict at `rate` [Hz] over every operating point of `lin`."""
    with pdloop.one_blas_thread():
        h = zoh.reduce(lin, pid)
        hold = 1.0 / rate
        rho = zoh.radii(h, pid, hold)
        ok = bool(np.all(rho <= 1.0 + zoh.RADIUS_TOL))
        edge, worst = zoh.hold_max(h, pid, hold)
        remedy = None if ok else _remedy(h, pid, hold, edge)
    left = int(np.count_nonzero(~h.holds(pid)))
    return RateVerdict(rate, ok, edge, float(rho.max(initial=0.0)), worst, left, remedy)


def round_up(x: float, digits: int = RATE_DIGITS) -> float:
    """X rounded up to `digits` significant digits (a rate still above a bound)."""
    if x <= 0 or not math.isfinite(x):
        return x
    step = 10.0 ** (math.floor(math.log10(x)) - digits + 1)
    return float(f"{math.ceil(x / step - 1e-9) * step:.{digits}g}")


def _remedy(h: zoh.Held, pid: Pid, hold: float, edge: float) -> Remedy:
    """The rate that passes (gains kept), and the gains that pass at this rate."""
    rate: int | None = None
    if edge > 0 and math.isfinite(edge):
        want = 1.0 / (STABLE_MARGIN * edge)
        for _ in range(RETRIES):
            r = int(round_up(want))
            if zoh.stable(h, pid, 1.0 / r):
                rate = r
                break
            want = r / STABLE_MARGIN
    s = zoh.gain_scale(h, pid, hold)
    held = h.take(h.holds(pid))  # lower gains must hold the arm where these do
    for _ in range(RETRIES if s is not None else 0):
        assert s is not None
        kp, kd, ki = (
            tuple(round_down(float(x)) for x in g) for g in _gains(pid.scaled(STABLE_MARGIN * s))
        )
        rounded = Pid(pdloop.PD.of(pid.pd.idx, kp, kd, pid.pd.damping), np.array(ki, dtype=float))
        if zoh.holds_stably(held, rounded, hold):
            return Remedy(rate, STABLE_MARGIN * s, kp, kd, ki)
        s *= STABLE_MARGIN
    return Remedy(rate, None, None, None, None)


def _gains(pid: Pid) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return pid.pd.kp, pid.pd.kd, pid.ki


def message(
    v: RateVerdict,
    names: Sequence[str],
    q: Sequence[float],
    *,
    what: str,
    rate_name: str,
    gain_names: tuple[str, str, str] = ("p", "d", "i"),
) -> str:
    """The sentence for an unstable held loop: rate, hold, where, the edge and both remedies.

    `what` names the controller ("arm_controller"), `rate_name` the parameter to change,
    `gain_names` the P, D and I gains as the file being fixed calls them.
    """
    where = ", ".join(f"{n} = {x:.3g}" for n, x in zip(names, q, strict=True))
    if v.hold_max > 0:
        edge = (
            f"stable for a hold <= {v.hold_max * 1e3:.3g} ms "
            f"({rate_name} >= {round_up(v.rate_min, 3):g} Hz)"
        )
    else:
        edge = "stable at no rate: the gains are not damped enough for any hold"
    text = (
        f"{what} at {v.rate:g} Hz holds its effort for {v.hold * 1e3:.3g} ms between updates "
        f"(gz_ros2_control): the loop diverges at {where} (spectral radius "
        f"{v.radius:.3g} per update > 1); {edge}"
    )
    if v.remedy is None:
        return text
    return f"{text}; {remedy_text(v.remedy, names, rate_name, gain_names)}"


def remedy_text(
    r: Remedy, names: Sequence[str], rate_name: str, gain_names: tuple[str, str, str]
) -> str:
    """Both remedies in words: the rate, or the gains scaled at this rate."""
    parts = []
    if r.rate is not None:
        physics = (
            f", or {GZ_PHYSICS_RATE} (Gazebo's physics rate)" if r.rate < GZ_PHYSICS_RATE else ""
        )
        parts.append(f"e.g. {rate_name} {r.rate}{physics}")
    if r.kp is not None and r.kd is not None and r.ki is not None and r.factor is not None:
        p_, d_, i_ = gain_names
        text = f"keep the rate with {p_} and {d_} x {r.factor:.3g}"
        if any(k > 0 for k in r.ki):
            text += f", {i_} x {r.factor**2:.3g}"
        if len(names) <= LIST_GAINS:
            each = zip(names, r.kp, r.kd, r.ki, strict=True)
            text += (
                " ("
                + ", ".join(
                    f"{n} {p_} {p:g} {d_} {d:g}" + (f" {i_} {i:g}" if i > 0 else "")
                    for n, p, d, i in each
                )
                + ")"
            )
        parts.append(text)
    return "; or ".join(parts) if parts else "lower the gains"
