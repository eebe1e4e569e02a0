"""Tracking metrics, the summary table and joint-state output (CSV/JSON) of a simulation.

The output mimics Gazebo's joint_state_publisher: one row per publish period (the
spec's `joint_state_publisher.update_rate`, 10 Hz) with position, velocity and effort of
every joint, plus the reference the controller was tracking.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from armcli.errors import InputError
from armcli.io.files import write_file_atomic
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


def summary_table(
    metrics: Sequence[JointMetrics], ee: np.ndarray | None, ee_label: str, res: SimResult
) -> Any:
    """A rich Table; the caller prints it."""
    from rich.table import Table
    from rich.text import Text

    caption = (
        f"{res.integrator}, dt = {res.dt:g} s, {len(res.t) - 1} steps, {res.backend} engine "
        f"({res.wall_time * 1e6 / max(1, len(res.t) - 1):.2f} µs/step)\n"
        f"errors q - q_ref [rad]; settle: time after the last point until |error| stays "
        f"< {SETTLE_TOL:g}"
    )
    if ee is not None:
        caption += f"\nend effector {ee_label} at t = {res.t[-1]:g} s: " + _xyz(ee)
    table = Table(title="armcli simulate: tracking", caption=Text(caption), caption_justify="left")
    table.add_column("joint", no_wrap=True)
    for col in ("RMS err", "max err", "final err", "settle [s]", "saturated", "stop hits"):
        table.add_column(Text(col), justify="right")
    for m in metrics:
        table.add_row(
            m.name,
            f"{m.rms_error:.4f}",
            f"{m.max_error:.4f}",
            f"{m.final_error:+.4f}",
            "not settled" if m.settle_time is None else f"{m.settle_time:.3f}",
            f"{m.saturated_pct:.1f}%",
            str(m.limit_contacts),
        )
    return table


def _xyz(p: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.4f}" for x in p) + ") m"


def sample_states(res: SimResult, rate: float) -> dict[str, np.ndarray]:
    """Columns `time`, `NAME.position|velocity|effort|reference` at `rate` [Hz]."""
    steps = len(res.t) - 1
    period = 1.0 / rate
    n_samples = int(np.floor(res.t[-1] / period + 1e-9)) + 1
    idx = np.minimum(np.round(np.arange(n_samples) * period / res.dt).astype(int), steps)
    tau_idx = np.minimum(idx, steps - 1)
    cols: dict[str, np.ndarray] = {"time": res.t[idx]}
    for i, name in enumerate(res.joint_names):
        cols[f"{name}.position"] = res.q[idx, i]
        cols[f"{name}.velocity"] = res.v[idx, i]
        cols[f"{name}.effort"] = res.tau[tau_idx, i]
        cols[f"{name}.reference"] = res.q_ref[idx, i]
    return cols


def states_bytes(cols: dict[str, np.ndarray], fmt: str) -> bytes:
    """CSV or JSON text of the sampled states (deterministic formatting)."""
    names = list(cols)
    if fmt == "json":
        data = {k: [float(FLOAT_FMT.format(x)) for x in v] for k, v in cols.items()}
        return (json.dumps(data, indent=1) + "\n").encode()
    lines = [",".join(names)]
    rows = np.column_stack([cols[k] for k in names])
    lines += [",".join(FLOAT_FMT.format(x) for x in row) for row in rows]
    return ("\n".join(lines) + "\n").encode()


def output_format(path: Path) -> str:
    """The joint-state file format named by the extension of `path`: "csv" or "json".

    Raises:
        InputError: any other extension.
    """
    ext = path.suffix.lower()
    if ext not in (".csv", ".json"):
        raise InputError(
            f"unknown output format {ext or '(none)'!r}; use .csv or .json", field="--output"
        )
    return ext[1:]


def write_states(path: Path, res: SimResult, rate: float) -> None:
    """Write the joint states sampled at `rate` [Hz] atomically, as CSV or JSON by extension."""
    write_file_atomic(path, states_bytes(sample_states(res, rate), output_format(path)))
