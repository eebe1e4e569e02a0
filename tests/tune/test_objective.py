"""The objective's arithmetic against hand-computed values from its documented formula."""

from __future__ import annotations

import numpy as np
import pytest

from armcli.tune.objective import INFEASIBLE_COST, METRIC_FIELDS, Weights, aggregate, run_cost


def test_run_cost_is_the_documented_sum() -> None:
    # Two joints: rms 0.01 / 0.03, saturated 20 % / 0 %, overshoot 15 % / 2 %, settle 0.4 / 0.1 s.
    rows = {"rms": (0.01, 0.03), "max": (0.0, 0.0), "final": (0.0, 0.0),
            "settle": (0.4, 0.1), "saturated": (0.2, 0.0), "overshoot": (0.15, 0.02)}  # fmt: skip
    metrics = np.array([[rows[f][j] for f in METRIC_FIELDS] for j in range(2)])
    w = Weights()
    # mean rms 0.02 + 0.1 * mean sat 0.1 + 0.1 * (0.15 - 0.05) + 0.01 * max settle 0.4
    expected = 0.02 + 0.1 * 0.1 + 0.1 * 0.10 + 0.01 * 0.4
    assert run_cost(metrics, w) == pytest.approx(expected, rel=1e-12)


def test_aggregate_worst_and_quantile() -> None:
    costs = np.array([[1.0, 3.0], [2.0, 2.0], [5.0, 1.0]])  # models x trajectories
    # Means over trajectories per model: 2, 2, 3.
    assert aggregate(costs, True, "worst", 0.9) == 3.0
    assert aggregate(costs, True, "quantile", 0.5) == 2.0
    assert aggregate(costs, False, "worst", 0.9) == INFEASIBLE_COST
    assert aggregate(np.array([[1.0, np.inf]]), True, "worst", 0.9) == INFEASIBLE_COST
