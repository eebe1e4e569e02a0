"""Tracking metrics and the summary table of a simulation (the states file: sim/states.py)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.io.terminal import Column, FitTable
from armcli.sim.simulate import SimResult

SETTLE_TOL = 0.01  # [rad or m] |q - q_ref| band for "settled"
FLOAT_FMT = "{:.9g}"


@dataclass(frozen=True)
class JointMetrics:
    """How well one joint tracked its reference; errors in the joint's unit [rad or m]."""

    name: str
    rms_error: float  # over the whole run
    max_error: float
    final_error: float  # q - q_ref at the end (signed)
    settle_time: float | None  # [s] after the last trajectory point; None: not settled
    saturated_pct: float  # % of steps with the motor torque at the effort limit
    limit_contacts: int  # times a joint stop engaged (rising edges)


def joint_metrics(res: SimResult, t_end: float, tol: float = SETTLE_TOL) -> list[JointMetrics]:
    """Per-joint tracking metrics; `t_end` is the time of the trajectory's last point."""
    err = res.q - res.q_ref
    out = []
    for i, name in enumerate(res.joint_names):
        e = err[:, i]
        stop = res.stop_active[:, i]
        rises = int(stop[0]) + int(np.count_nonzero(stop[1:] & ~stop[:-1]))
        out.append(
            JointMetrics(
                name=name,
                rms_error=float(np.sqrt(np.mean(e**2))),
                max_error=float(np.max(np.abs(e))),
                final_error=float(e[-1]),
                settle_time=_settle(res.t, e, t_end, tol),
                saturated_pct=float(100.0 * np.mean(res.saturated[:, i])),
                limit_contacts=rises,
            )
        )
    return out


def _settle(t: np.ndarray, e: np.ndarray, t_end: float, tol: float) -> float | None:
    outside = np.nonzero(np.abs(e) > tol)[0]
    if outside.size and outside[-1] == len(e) - 1:
        return None
    start = t[outside[-1] + 1] if outside.size else t[0]
    return max(0.0, float(start) - t_end)


SUMMARY_HEADERS = (
    "RMS err\n[rad]",
    "max err\n[rad]",
    "final err\n[rad]",
    "settle\n[s]",
    "saturated\n[%]",
    "stop\nhits",
)
ENGINE_LABEL = {"native": "compiled (native)", "python": "Python"}


def summary_table(
    metrics: Sequence[JointMetrics], ee: np.ndarray | None, ee_label: str, res: SimResult
) -> Any:
    """A table (rich renderable, numbers whole at any width); the caller prints it."""
    caption = (
        f"{res.integrator}, dt = {res.dt:g} s, {len(res.t) - 1} steps, "
        f"{ENGINE_LABEL.get(res.backend, res.backend)} engine "
        f"({res.wall_time * 1e6 / max(1, len(res.t) - 1):.2f} µs/step)\n"
        f"errors q - q_ref; settle: time after the last point until |error| stays "
        f"< {SETTLE_TOL:g}; stop hits: times a joint stop engaged"
    )
    if ee is not None:
        caption += f"\nend effector {ee_label} at t = {res.t[-1]:g} s:\n  " + _xyz(ee)
    table = FitTable(
        [Column("joint", number=False), *(Column(h) for h in SUMMARY_HEADERS)],
        title="armcli simulate: tracking",
        caption=caption,
    )
    for m in metrics:
        table.add_row(
            m.name,
            f"{m.rms_error:.4f}",
            f"{m.max_error:.4f}",
            f"{m.final_error:+.4f}",
            "not settled" if m.settle_time is None else f"{m.settle_time:.3f}",
            f"{m.saturated_pct:.1f}",
            str(m.limit_contacts),
        )
    return table


def _xyz(p: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.4f}" for x in p) + ") m"
