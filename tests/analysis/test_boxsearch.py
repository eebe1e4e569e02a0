"""The projected-gradient search finds what scipy's L-BFGS-B finds within the same box."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from armcli.analysis.boxsearch import minimize_box

TOL = 1e-6  # objective agreement between two local solvers stopping at their own tolerances


def rosenbrock(x: np.ndarray) -> tuple[float, np.ndarray]:
    f = 100.0 * (x[1] - x[0] ** 2) ** 2 + (1 - x[0]) ** 2
    g = np.array([-400.0 * x[0] * (x[1] - x[0] ** 2) - 2 * (1 - x[0]), 200.0 * (x[1] - x[0] ** 2)])
    return float(f), g


def two_link_tip_height(x: np.ndarray) -> tuple[float, np.ndarray]:
    """Minus the tip height of a planar 0.3 m + 0.3 m arm (a typical reach objective)."""
    z = 0.3 * np.cos(x[0]) + 0.3 * np.cos(x[0] + x[1])
    g = np.array([0.3 * np.sin(x[0]) + 0.3 * np.sin(x[0] + x[1]), 0.3 * np.sin(x[0] + x[1])])
    return -float(z), g


@pytest.mark.parametrize(
    ("fun", "x0", "lo", "hi"),
    [
        (rosenbrock, [-0.5, 0.5], [-2.0, -2.0], [0.5, 0.2]),  # minimum on the bound
        (two_link_tip_height, [1.0, 1.2], [0.3, 0.2], [1.5, 1.5]),  # a corner
        (lambda x: (float(np.sum((x - 0.3) ** 2)), 2 * (x - 0.3)), [1, -1, 0.5], [-1] * 3, [1] * 3),
    ],
)
def test_same_minimum_as_lbfgsb(fun, x0, lo, hi) -> None:  # type: ignore[no-untyped-def]
    ours = minimize_box(fun, x0, lo, hi, max_iterations=20000)
    ref = minimize(
        fun,
        np.asarray(x0, float),
        jac=True,
        method="L-BFGS-B",
        bounds=list(zip(lo, hi, strict=True)),
    )
    assert ours.f == pytest.approx(float(ref.fun), abs=TOL)
    assert np.all(ours.x >= np.asarray(lo)) and np.all(ours.x <= np.asarray(hi))
