"""`--plot`: the optimisation history and the before/after tracking on one trajectory.

matplotlib (Agg) is imported inside the function so importing armcli stays cheap.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from typing import Any

import numpy as np

from armcli.sim.simulate import SimResult
from armcli.tune.objective import INFEASIBLE_COST
from armcli.tune.search import TrialRecord


def tune_png(
    history: Sequence[TrialRecord], runs: Sequence[tuple[str, SimResult]], case_label: str
) -> bytes:
    """PNG bytes: the history on top, one tracking-error panel per joint below.

    Errors rather than positions: at this scale the position curves would overlap.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = runs[0][1].joint_names
    fig = plt.figure(figsize=(5.0 * max(2, len(names)), 8.0))
    grid = fig.add_gridspec(2, len(names))
    _history(fig.add_subplot(grid[0, :]), history)
    for i, name in enumerate(names):
        axj = fig.add_subplot(grid[1, i])
        axj.axhline(0.0, color="0.4", lw=1.0, ls="--")
        for k, (label, res) in enumerate(runs):
            axj.plot(res.t, res.q[:, i] - res.q_ref[:, i], color=f"C{k + 2}", lw=1.2, label=label)
        axj.set_title(f"{name}: tracking on {case_label}", fontsize=10)
        axj.set_xlabel("time [s]")
        axj.set_ylabel("error q - q_ref [rad]")
        axj.grid(True, alpha=0.3)
        axj.legend(loc="best", fontsize=8)
    fig.suptitle("armcli tune", fontsize=12)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def _history(ax: Any, history: Sequence[TrialRecord]) -> None:
    """Cost per trial (log scale), best so far, infeasible trials as crosses on top."""
    cost = np.array([r.cost for r in history])
    ok = cost < INFEASIBLE_COST
    x = np.arange(1, len(cost) + 1)
    ax.semilogy(x[ok], cost[ok], "o", ms=4, color="C0", label="trial")
    if (~ok).any():
        top = cost[ok].max() if ok.any() else 1.0
        ax.plot(x[~ok], np.full((~ok).sum(), top), "x", color="C3", label="infeasible")
    best = np.minimum.accumulate(np.where(ok, cost, np.inf))
    ax.step(x, best, where="post", color="C1", lw=1.5, label="best so far")
    ax.set_xlabel("trial")
    ax.set_ylabel("objective [rad]")
    ax.set_title("optimisation history")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize=8)
