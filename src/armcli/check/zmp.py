"""Rules `zmp-outside-support` and `zmp-margin`: does a trajectory tip the robot over?

With `--trajectory` and a spec's gains, the spec's arm is simulated along the file as
`armcli simulate` does (sim.armrun), and the whole robot's zero-moment point, with the
base also accelerating and braking at the diff-drive plugin's limit, is measured against
the support polygon (`check/tipover.py` builds the stance). One finding for the run's
worst moment, naming the time, the case and the base acceleration that still holds. An
error only when the point stays outside long enough to rotate the robot over the edge
(analysis.excursion, docs/check.md); a shorter excursion lifts a wheel: a warning.
"""

from __future__ import annotations

import math

from armcli.check.context import Context
from armcli.check.findings import Value
from armcli.check.tipover import round_down
from armcli.errors import ArmcliError


def check(c: Context) -> None:
    """Simulate the trajectory (when asked) and report its worst zero-moment point."""
    opts, spec = c.opts.tipover, c.opts.spec
    if opts.trajectory is None or c.stance is None:
        return
    if spec is None or not spec.control.gains:
        c.notes.append(
            "zero-moment point skipped: the trajectory needs a spec's PD gains "
            "to be simulated (give --spec)"
        )
        return
    from armcli.sim import armrun  # the simulator's stack: only with --trajectory (~60 ms)
    from armcli.urdf.source import RobotFile

    file = c.opts.robot_file if c.opts.robot_file is not None else RobotFile.of_spec(spec)
    try:
        r = armrun.trajectory_zmp(
            file, c.urdf, c.stance, opts.trajectory, opts.base_accel, opts.min_margin
        )
    except ArmcliError as exc:
        c.notes.append(f"zero-moment point skipped: {exc}")
        return
    c.zmp = r
    if r.min_margin >= opts.min_margin:
        return
    if r.tips:
        what = f"{-r.min_margin * 1e3:.1f} mm outside the support polygon: the robot tips"
    elif r.min_margin < 0:  # too briefly to rotate the robot over the edge (sim.tipping)
        lift = sum(e.duration for e in r.lifts)
        what = (
            f"{-r.min_margin * 1e3:.1f} mm outside the support polygon for {lift:.3f} s: "
            "a wheel lifts off, too briefly to tip the robot"
        )
    else:
        what = (
            f"only {r.min_margin * 1e3:.1f} mm inside the support polygon "
            f"(threshold {opts.min_margin * 1e3:g} mm)"
        )
    holds = r.max_base_accel if r.tips else r.max_base_accel_margin
    fix: dict[str, Value] = {}
    text = (
        f"trajectory {opts.trajectory.name}: zero-moment point {what}, toward "
        f"{r.direction} at t = {r.time:.3f} s ({r.when}); "
    )
    if holds > 0 and math.isfinite(holds):
        text += f"a base acceleration up to {holds:.3g} m/s² holds"
        # the spec's diff_drive field when the limit came from the plugin, else the option
        key = "base_accel" if opts.base_accel is not None else "max_wheel_acceleration"
        fix[key] = round_down(holds)
    elif math.isinf(holds):
        text += "the base's acceleration does not move it toward that edge"
    else:
        text += "the arm motion alone is too fast: slow the trajectory down"
    rule = "zmp-outside-support" if r.tips else "zmp-margin"
    c.out.add(
        rule,
        c.urdf.line,
        text,
        fix,
        time=r.time,
        margin=r.min_margin,
        case=r.case,
        base_accel=r.base_accel,
        direction=r.direction,
        zmp=list(r.zmp),
        trajectory=str(opts.trajectory),
    )
