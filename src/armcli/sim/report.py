"""Tracking metrics and the summary table of a simulation (the states file: sim/states.py)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.io.terminal import Column, FitTable
from armcli.sim.simulate import SETTLE_TOL, SimResult

__all__ = ["SETTLE_TOL", "JointMetrics", "joint_metrics", "summary_table"]


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


def joint_metrics(res: SimResult, t_end: float) -> list[JointMetrics]:
    """Per-joint tracking metrics over every state of the run, kept or not.

    `t_end` is the time of the trajectory's last point. The engine accumulates the
    statistics step by step (`res.stats`).
    """
    st = res.stats
    out = []
    for i, name in enumerate(res.joint_names):
        last = int(st.last_out[i])  # the last state outside the band; -1: none
        start = (last + 1) * res.dt if last >= 0 else 0.0
        settle = None if last == res.steps else max(0.0, start - t_end)
        out.append(
            JointMetrics(
                name=name,
                rms_error=float(np.sqrt(st.sum_e2[i] / st.states)),
                max_error=float(st.max_e[i]),
                final_error=float(st.last_e[i]),
                settle_time=settle,
                saturated_pct=float(100.0 * st.saturated_steps[i] / res.steps),
                limit_contacts=int(st.stop_rises[i]),
            )
        )
    return out


SUMMARY_HEADERS = (
    "RMS err\n[rad]",
    "max err\n[rad]",
    "final err\n[rad]",
    "settle\n[s]",
    "saturated\n[%]",
    "stop\nhits",
)


def summary_table(
    metrics: Sequence[JointMetrics],
    ee: np.ndarray | None,
    ee_label: str,
    res: SimResult,
    engine: str | None = None,
) -> Any:
    """A table (rich renderable, numbers whole at any width); the caller prints it.

    `engine` names another engine than the compiled one (a drive run's MuJoCo).
    """
    per_step = f"{res.wall_time * 1e6 / max(1, res.steps):.2f} µs/step"
    engine = engine or f"{res.integrator}, compiled engine ({per_step})"
    caption = (
        f"dt = {res.dt:g} s, {res.steps} steps, {engine}\n"
        f"errors q - q_ref; settle: time after the last point until |error| stays "
        f"< {res.settle_tol:g}; stop hits: times a joint stop engaged"
    )
    if ee is not None:
        caption += f"\nend effector {ee_label} at t = {res.steps * res.dt:g} s:\n  " + _xyz(ee)
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
