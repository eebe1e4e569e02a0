"""Tracking plot: reference vs actual position, velocity and motor torque per joint.

matplotlib is imported inside the function so that importing armcli stays cheap, and
drawn the cheap way (issue 31: the plot was 65 % of `simulate --plot`): a bare Figure on
the Agg canvas (pyplot's import alone cost more than the run), fixed margins instead of
`tight_layout`'s measuring pass, legends in a fixed corner (loc="best" searches every
point) and at most PLOT_POINTS states per line, about two per pixel column.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from armcli.sim.simulate import SimResult

PLOT_POINTS = 1000  # states a line draws at most: ~2 per pixel of a 500 px wide panel


def plot_steps(steps: int) -> np.ndarray:
    """The steps whose states a plot of a `steps`-step run needs (evenly spread, both ends)."""
    picks = np.round(np.linspace(0, steps, min(steps + 1, PLOT_POINTS))).astype(np.int64)
    return picks[np.concatenate(([True], picks[1:] != picks[:-1]))]  # increasing already


def tracking_png(
    res: SimResult,
    effort_limits: np.ndarray | None = None,
    extra_row: Callable[[Sequence[Any]], None] | None = None,
    rows: int = 1,
    title: str | None = None,
) -> bytes:
    """PNG bytes of a rows = (position, velocity, torque), columns = joints figure.

    `extra_row` draws `rows` more rows, given their axes row after row (the zero-moment
    point's, sim.tipping; a drive's path and wheel loads, drive.output).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = len(res.joint_names)
    extra = 0 if extra_row is None else rows
    fig = Figure(figsize=(5.0 * n, 2.5 * (3 + extra)))
    FigureCanvasAgg(fig)
    axes = fig.subplots(3 + extra, n, sharex=False, squeeze=False)
    for ax in axes[: 4 if extra == 1 else 3].ravel()[1:]:  # the time rows (a path is not one)
        ax.sharex(axes[0, 0])
    t = res.t  # the states the run kept (simulate's plot_steps: dense enough to draw)
    for i, name in enumerate(res.joint_names):
        ax_q, ax_v, ax_t = axes[:3, i]
        ax_q.plot(t, res.q_ref[:, i], "--", color="0.4", lw=1.5, label="reference")
        ax_q.plot(t, res.q[:, i], color="C0", lw=1.2, label="actual")
        ax_v.plot(t, res.v_ref[:, i], "--", color="0.4", lw=1.5, label="reference")
        ax_v.plot(t, res.v[:, i], color="C1", lw=1.2, label="actual")
        ax_t.plot(t, res.tau[:, i], color="C2", lw=1.2, label="motor torque")
        sat = res.saturated[:, i]
        if sat.any() and effort_limits is not None:
            for s in (-1, 1):
                ax_t.axhline(s * effort_limits[i], color="C3", lw=0.8, ls=":", label=None)
            ax_t.fill_between(
                t,
                0,
                1,
                where=sat,
                color="C3",
                alpha=0.15,
                transform=ax_t.get_xaxis_transform(),
                label="saturated",
            )
        ax_q.set_title(name, fontsize=11)
        ax_q.set_ylabel("position [rad]")
        ax_v.set_ylabel("velocity [rad/s]")
        ax_t.set_ylabel("torque [N·m]")
        ax_t.set_xlabel("time [s]")
        for ax in (ax_q, ax_v, ax_t):
            ax.grid(True, alpha=0.3)
            ax.legend(loc="upper right", fontsize=8)
    if extra_row is not None:
        extra_row(list(axes[3:].ravel()) if rows > 1 else axes[3])
    title = title or f"armcli simulate ({res.integrator}, dt = {res.dt:g} s)"
    # fixed margins [in]: room for the y labels, the titles and the x labels; the figure's
    # title a fixed distance from the top, above the first row's titles at any height
    w, h = fig.get_size_inches()
    fig.suptitle(title, fontsize=12, y=1 - 0.1 / h, va="top")
    fig.subplots_adjust(
        left=0.75 / w, right=1 - 0.2 / w, bottom=0.5 / h, top=1 - 0.8 / h, hspace=0.45, wspace=0.3
    )
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    return buf.getvalue()
