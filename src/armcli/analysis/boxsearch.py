"""Local minimisation of a smooth function of the joint values within their limits.

Projected gradient descent with an Armijo backtracking step along the projection arc
(Bertsekas, Nonlinear Programming, 2.3): each step moves against the gradient and is
clipped into the box of joint limits. It finds the same minima as scipy's L-BFGS-B on
the balance and reach problems (the tests compare them) while costing `check` none of
scipy.optimize's ~0.5 s of import.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

Objective = Callable[[NDArray[np.float64]], tuple[float, NDArray[np.float64]]]

MAX_ITERATIONS = 200
ARMIJO = 1e-4  # sufficient decrease along the projection arc
MIN_STEP = 1e-12
F_TOL = 1e-12  # stop when an accepted step gains less than this


@dataclass(frozen=True)
class Minimum:
    """Where a local search ended and the value there."""

    x: NDArray[np.float64]
    f: float
    iterations: int


def minimize_box(
    fun: Objective,
    x0: ArrayLike,
    lower: ArrayLike,
    upper: ArrayLike,
    *,
    step: float = 1.0,
    max_iterations: int = MAX_ITERATIONS,
) -> Minimum:
    """A local minimum of `fun` (value, gradient) within lower <= x <= upper from x0.

    `step` is the first trial step length [x units per gradient unit]; it doubles after
    each accepted step and halves until the Armijo condition holds.
    """
    lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    x = np.clip(np.asarray(x0, dtype=float), lo, hi)
    f, g = fun(x)
    k = 0
    for k in range(1, max_iterations + 1):
        while True:
            xn = np.clip(x - step * g, lo, hi)
            moved = xn - x
            if not np.any(moved):
                return Minimum(x, f, k)  # a corner or a stationary point: nothing to gain
            fn, gn = fun(xn)
            if fn <= f + ARMIJO * float(g @ moved):
                break
            step *= 0.5
            if step < MIN_STEP:
                return Minimum(x, f, k)
        gained = f - fn
        x, f, g = xn, fn, gn
        if gained < F_TOL:
            break
        step *= 2.0
    return Minimum(x, f, k)
