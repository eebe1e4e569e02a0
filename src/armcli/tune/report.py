"""Tuning results for people and programs: tables and the JSON document.

The JSON schema is in docs/tune.md; `SCHEMA_VERSION` changes on breaking changes.

Per-joint figures come from the nominal model and aggregate the trajectories: RMS is the
mean over trajectories, max and |final| the largest, settle the longest, saturated the
mean share of steps. The stability margin is dt_max / dt for the chosen loop
(scalar-mode bound of `armcli.analysis.stability` with the joint's lambda_j = max (M^-1)_jj).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.io.terminal import Column, FitTable
from armcli.tune import gains as gain_vector
from armcli.tune.evaluate import CandidateEval
from armcli.tune.model_gains import StartGains, dt_max
from armcli.tune.objective import FINAL, MAX, RMS, SATURATED, SETTLE
from armcli.tune.problem import TuneProblem, describe
from armcli.tune.search import SearchOptions, SearchResult, TrialRecord

SCHEMA_VERSION = 1


@dataclass(frozen=True, eq=False)
class Row:
    """One labelled gain set ("spec", "start", "tuned") and its nominal evaluation."""

    label: str
    gains: np.ndarray  # [kp..., kd...]
    nominal: CandidateEval
    robust_cost: float | None  # the aggregate over the perturbed models, when robust


def joint_summary(ev: CandidateEval, j: int) -> dict[str, float | None]:
    """Aggregated nominal metrics of joint j (see the module docstring)."""
    m = ev.metrics[0, :, j, :]
    if not ev.feasible:
        return {k: None for k in ("rms", "max", "final", "settle", "saturated_pct")}
    return {
        "rms": float(np.mean(m[:, RMS])),
        "max": float(np.max(m[:, MAX])),
        "final": float(np.max(np.abs(m[:, FINAL]))),
        "settle": float(np.max(m[:, SETTLE])),
        "saturated_pct": float(100.0 * np.mean(m[:, SATURATED])),
    }


def margin(start: StartGains, j: int, kp: float, kd: float, damping: float) -> float:
    """dt_max / dt of joint j's gains for the chosen loop [-]."""
    return dt_max(start.loop, kp, kd + damping, float(start.lambda_joint[j])) / start.dt


REASONING_COLUMNS = (
    ("joint", False),
    ("M_jj\n[kg·m²]", True),
    ("|g| max\n[N·m]", True),
    ("step\n[rad]", True),
    ("ωn goal\n[rad/s]", True),
    ("stab.\n[rad/s]", True),
    ("effort\n[rad/s]", True),
    ("ωn\n[rad/s]", True),
    ("ζ", True),
    ("kp", True),
    ("kd", True),
    ("binding", False),
)
REASONING_CAPTION = (
    "M_jj: min..max over the sampled poses; ωn = the smallest of the goal and the "
    "stability and effort caps (binding: which one), scaled down when the coupled loop "
    "needs it; kp [N·m/rad], kd [N·m·s/rad]; prismatic joints in kg, N, m"
)


def reasoning_table(start: StartGains) -> Any:
    """A table of the model-based start, one row per joint (numbers whole at any width)."""
    t = FitTable(
        [Column(h, n) for h, n in REASONING_COLUMNS],
        title=f"model-based start ({start.loop} loop, dt = {start.dt:g} s)",
        caption=REASONING_CAPTION,
    )
    for r in start.rows:
        t.add_row(
            r.name,
            _range(r.m_min, r.m_max),
            f"{r.gravity_max:.3g}",
            f"{r.step:.3g}",
            f"{r.wn_target:.3g}",
            f"{r.wn_stability:.3g}",
            f"{r.wn_effort:.3g}",
            f"{r.wn:.4g}",
            f"{r.zeta:g}",
            f"{r.kp:.4g}",
            f"{r.kd:.4g}",
            r.binding,
        )
    return t


COMPARISON_COLUMNS = (
    ("gains", False),
    ("kp", True),
    ("kd", True),
    ("RMS\n[rad]", True),
    ("max\n[rad]", True),
    ("|final|\n[rad]", True),
    ("settle\n[s]", True),
    ("saturated\n[%]", True),
    ("margin\n[x]", True),
)
COMPARISON_CAPTION = (
    "errors q - q_ref; kp [N·m/rad], kd [N·m·s/rad]; margin: dt_max / dt of the loop "
    "(above 1 is stable)"
)


def comparison_table(
    problem: TuneProblem, start: StartGains, rows: Sequence[Row], damping: np.ndarray
) -> Any:
    """Per joint (a group) and gain set: gains, errors, settle, saturation, margin."""
    t = FitTable(
        [Column(h, num) for h, num in COMPARISON_COLUMNS],
        title="before / after (nominal model, all trajectories)",
        caption=COMPARISON_CAPTION,
    )
    for j, name in enumerate(problem.joints):
        t.add_group(name)
        for row in rows:
            s = joint_summary(row.nominal, j)
            kp, kd = gain_vector.of_joint(row.gains, j)
            cells = [_f(s[k]) for k in ("rms", "max", "final", "settle")]
            sat = "-" if s["saturated_pct"] is None else f"{s['saturated_pct']:.1f}"
            t.add_row(
                row.label,
                f"{kp:.4g}",
                f"{kd:.4g}",
                *cells,
                sat,
                f"{margin(start, j, kp, kd, float(damping[j])):.3g}",
            )
    return t


def _range(lo: float, hi: float) -> str:
    a, b = f"{lo:.3g}", f"{hi:.3g}"
    return a if a == b else f"{a}..{b}"


def _f(x: float | None) -> str:
    return "-" if x is None else f"{x:.4g}"


def to_json(
    problem: TuneProblem,
    start: StartGains,
    rows: Sequence[Row],
    result: SearchResult,
    opts: SearchOptions,
    engine: str,
    damping: np.ndarray,
) -> str:
    """The output document (schema in docs/tune.md; stable key order, no timestamps)."""
    best_kp, best_kd = gain_vector.split(result.best)
    search = {k: getattr(opts, k) for k in ("trials", "batch", "seed", "span", "robust")}
    doc = {
        "schema_version": SCHEMA_VERSION,
        "problem": describe(problem),
        "search": {
            **search,
            "quantile": opts.quantile,
            "engine": engine,
            "weights": vars(opts.weights),
        },
        "start": [
            {k: _num(v) if isinstance(v, float) else v for k, v in vars(r).items()}
            for r in start.rows
        ],
        "results": {row.label: _row_doc(problem, start, row, damping) for row in rows},
        "best": {
            "cost": _num(result.best_cost),
            "kp": best_kp.tolist(),
            "kd": best_kd.tolist(),
        },
        "history": [_trial_doc(r) for r in result.history],
    }
    return json.dumps(doc, indent=2, allow_nan=False) + "\n"


def _row_doc(
    problem: TuneProblem, start: StartGains, row: Row, damping: np.ndarray
) -> dict[str, Any]:
    return {
        "robust_cost": _num(row.robust_cost),
        "feasible": row.nominal.feasible,
        "joints": {
            name: _joint_doc(start, row, j, float(damping[j]))
            for j, name in enumerate(problem.joints)
        },
    }


def _trial_doc(r: TrialRecord) -> dict[str, Any]:
    return {
        "trial": r.number,
        "cost": _num(r.cost),
        "feasible": r.feasible,
        "reason": r.reason,
        "gains": r.gains.tolist(),
    }


def _joint_doc(start: StartGains, row: Row, j: int, damping: float) -> dict[str, Any]:
    kp, kd = gain_vector.of_joint(row.gains, j)
    summary = {k: _num(v) for k, v in joint_summary(row.nominal, j).items()}
    return {
        "kp": kp,
        "kd": kd,
        "stability_margin": _num(margin(start, j, kp, kd, damping)),
        **summary,
    }


def _num(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)
