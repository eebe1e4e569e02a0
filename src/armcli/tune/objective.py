"""The tuning objective: per-run metrics, their documented cost and the robust aggregate.

Cost of one run (one trajectory on one model), in radians (metres for prismatic joints):

    J = mean_j RMS_j                                    tracking error over the whole run
      + W_SATURATION * mean_j saturated_fraction_j      time spent at the effort limit
      + W_OVERSHOOT  * sum_j max(0, overshoot_j - max_overshoot)   (fractions of the step)
      + W_SETTLE     * max_j settle_j                   [s] after the last point

A candidate's cost on one model is the mean of J over the trajectories; over perturbed
models it is the worst case (default) or a quantile. A run that diverges, or gains that
violate the stability bound of the chosen loop, make the candidate infeasible: its cost
is INFEASIBLE_COST, far above any feasible cost, so the sampler learns to avoid it. The
nominal model must be stable at STABILITY_MARGIN * dt; with `--robust` each perturbed
model must be stable at dt (the perturbations take the place of the margin).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armcli.sim.report import SETTLE_TOL, joint_metrics
from armcli.sim.simulate import SimResult

W_SATURATION = 0.1  # [rad] cost of saturating during the whole run
W_OVERSHOOT = 0.1  # [rad] per unit of overshoot fraction beyond the bound
W_SETTLE = 0.01  # [rad/s] per second of settling after the last point
MAX_OVERSHOOT = 0.05  # overshoot allowed before it is penalised (5 % of the step)
INFEASIBLE_COST = 1e3  # [rad] cost of a diverging or unstable candidate
METRIC_FIELDS = ("rms", "max", "final", "settle", "saturated", "overshoot")
RMS, MAX, FINAL, SETTLE, SATURATED, OVERSHOOT = range(len(METRIC_FIELDS))


@dataclass(frozen=True)
class Weights:
    """Penalty weights of the objective (see the module docstring)."""

    saturation: float = W_SATURATION
    overshoot: float = W_OVERSHOOT
    settle: float = W_SETTLE
    max_overshoot: float = MAX_OVERSHOOT


def overshoot(res: SimResult, t_end: float) -> np.ndarray:
    """Per joint: how far q went past the final reference [fraction of the step].

    The step is the gap left at the last point; zero when it is within SETTLE_TOL. Reads
    the kept states from the last point's step on (`res` may keep only those).
    """
    after = res.step >= min(round(t_end / res.dt), res.steps)
    q_f = res.q_ref[-1]
    q_after = res.q[after]
    gap = q_f - q_after[0]
    past = np.sign(gap) * (q_after - q_f)  # > 0 beyond the target, in the approach direction
    peak = np.max(past, axis=0)
    scale = np.where(np.abs(gap) > SETTLE_TOL, np.abs(gap), np.inf)
    return np.where(np.abs(gap) > SETTLE_TOL, np.maximum(peak, 0.0) / scale, 0.0)


def run_metrics(res: SimResult, t_end: float) -> np.ndarray:
    """The (n_joints, len(METRIC_FIELDS)) metrics of one run.

    Settle is the whole window after the last point when the joint never settles.
    """
    window = float(res.t[-1]) - t_end
    rows = []
    for m, os in zip(joint_metrics(res, t_end), overshoot(res, t_end), strict=True):
        settle = m.settle_time if m.settle_time is not None else window
        rows.append([m.rms_error, m.max_error, m.final_error, settle, m.saturated_pct / 100.0, os])
    return np.array(rows, dtype=float)


def run_cost(metrics: np.ndarray, w: Weights) -> float:
    """J of one run from its metrics (see the module docstring)."""
    return float(
        np.mean(metrics[:, RMS])
        + w.saturation * np.mean(metrics[:, SATURATED])
        + w.overshoot * np.sum(np.maximum(0.0, metrics[:, OVERSHOOT] - w.max_overshoot))
        + w.settle * np.max(metrics[:, SETTLE])
    )


def aggregate(costs: np.ndarray, feasible: bool, robust: str, quantile: float) -> float:
    """Candidate cost from its per-(model, trajectory) costs.

    Mean over trajectories, then the worst model (`robust="worst"`) or the quantile.
    """
    if not feasible or not np.all(np.isfinite(costs)):
        return INFEASIBLE_COST
    per_model = np.mean(costs, axis=1)
    if robust == "quantile":
        return float(np.quantile(per_model, quantile))
    return float(np.max(per_model))
