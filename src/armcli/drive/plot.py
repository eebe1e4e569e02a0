"""A drive run's plot: the tracking plot with the path seen from above and the wheel loads.

With a world or a lidar, a last row shows one scan over the world (sim.sensors.plot).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from armcli.analysis.liftoff import TiltVerdict
from armcli.drive.job import DriveRun
from armcli.sim.simulate import SimResult

LOAD_WINDOW_S = 0.01  # [s] the wheel loads are drawn as means over this (a single step chatters)


def plot_png(run: DriveRun, res: SimResult, verdict_: TiltVerdict) -> bytes:
    """The tracking plot with two more rows: the path seen from above, the wheel loads."""
    from armcli.sim.plot import tracking_png

    title = f"armcli simulate --cmd-vel (MuJoCo, dt = {res.dt:g} s)"
    rows = 4 if _has_scene(run) else 2  # the scan seen from above takes two rows
    return tracking_png(res, run.job.arm.robot.effort, _drive_rows(run, verdict_), rows, title)


def _has_scene(run: DriveRun) -> bool:
    from armcli.sim.sensors.plot import pick_scan

    return bool(run.job.model.world) or pick_scan(run.readings) is not None


def _drive_rows(run: DriveRun, verdict_: TiltVerdict) -> Callable[[Sequence[Any]], None]:
    job, L, s = run.job, run.job.model.layout, run.sensors
    step = max(1, run.steps // 4000)
    window = max(1, round(LOAD_WINDOW_S / job.dt))

    def wide(row: Sequence[Any]) -> Any:
        """One axes across the figure in place of the per-joint axes of the rows given."""
        first, last = row[0].get_subplotspec(), row[-1].get_subplotspec()
        grid, fig = first.get_gridspec(), row[0].figure
        for a in row:
            a.remove()
        return fig.add_subplot(grid[first.rowspan.start : last.rowspan.stop, :])

    def draw(axes: Sequence[Any]) -> None:
        n = len(axes) // (4 if _has_scene(run) else 2)
        ax, load = wide(axes[:n]), wide(axes[n : 2 * n])
        if len(axes) > 2 * n:
            _scan_row(wide(axes[2 * n :]), run)
        pos = s[::step, L.base_pos]
        ax.plot(pos[:, 0], pos[:, 1], color="C0", lw=1.5, label=f"truth ({job.params.base_frame})")
        ax.plot(
            run.odometry.x[::step],
            run.odometry.y[::step],
            "--",
            color="C1",
            lw=1.2,
            label="odometry (wheel encoders)",
        )
        ax.plot(pos[0, 0], pos[0, 1], "o", color="k", ms=4, label="start")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title("path seen from above", fontsize=11)
        ax.legend(loc="best", fontsize=8)
        ax.grid(True, alpha=0.3)
        n = (len(s) // window) * window
        t = run.t[:n].reshape(-1, window).mean(axis=1)
        force = s[:n, L.touch].reshape(-1, window, len(job.model.contacts)).mean(axis=1)
        for i, link in enumerate(job.model.contacts):
            load.plot(t, force[:, i], lw=1.0, label=link)
        for lift in verdict_.lifts:
            load.axvspan(lift.start, lift.start + lift.duration, color="C3", alpha=0.25)
        load.set_xlabel("time [s]")
        load.set_ylabel("normal force [N]")
        load.set_title(
            f"wheel and caster loads ({LOAD_WINDOW_S * 1e3:g} ms means; shaded: lift-off)",
            fontsize=11,
        )
        load.legend(loc="best", fontsize=8)
        load.grid(True, alpha=0.3)

    return draw


def _scan_row(ax: Any, run: DriveRun) -> None:
    from armcli.drive.job import start_data
    from armcli.sim.sensors.plot import draw_scan

    job = run.job
    data = start_data(job.model, job.arm.q0)
    path = run.sensors[:, job.model.layout.base_pos][:, :2]
    draw_scan(ax, job.model.model, data, job.model.world, path, run.readings)
