"""`armcli plan` as one library call: output checked, robot read, planned, written, run.

`plan` refuses an output it must not write (one of its inputs; issue 42) and a plan it
could not execute (no PD gains) before any planning, plans, times and certifies the
request (plan.request), writes the trajectory and, when asked, runs it in the simulator
(plan.execute). `warn` hears what looks wrong in the request before the planning starts.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from armcli.errors import PlanningError
from armcli.io.files import write_file_atomic
from armcli.io.outdir import check_output_file
from armcli.plan.api import PlanOptions, PlanResult
from armcli.plan.execute import Execution, check_executable, execute
from armcli.plan.request import PlanRequest, plan_request
from armcli.sim.options import SimOptions
from armcli.urdf.source import RobotInput


@dataclass(frozen=True)
class Planned:
    """A planned (and maybe executed) motion, and the request in words."""

    result: PlanResult
    what: str  # `from home to reach`: what was planned
    executed: Execution | None = None  # the simulated run of the plan, when asked


def plan(
    robot: RobotInput,
    request: PlanRequest,
    options: PlanOptions,
    *,
    urdf: Path | None = None,
    output: Path | None = None,
    run: bool = False,
    warn: Callable[[str], None] | None = None,
) -> Planned:
    """Plan `request` for `robot` (or `urdf`), write it to `output`, `run` it in simulation."""
    if output is not None:  # never over a file it reads (issue 42; hard links too)
        inputs = [p for p in (urdf or robot.file(), request.srdf, request.scene) if p is not None]
        check_output_file(output, "output", inputs)
    robot_file = robot.read(urdf)
    if run:  # refused before planning: nothing written
        check_executable(robot_file.spec)
    what = request.describe()
    comment = f"armcli plan {what}, {options.planner}, seed {options.seed}"
    for line in request.warnings():
        if warn is not None:
            warn(line)
    try:
        result = plan_request(
            robot_file, replace(request, options=replace(options, comment=comment)), robot.packages
        )
    except PlanningError as exc:
        if exc.kind == "ik" and robot_file.spec is not None and robot_file.spec.mobile_base:
            why = f"{exc.reason}: out of the arm's reach from where the base stands"
            raise PlanningError(
                "ik", f"{why}; --base plans where to park and the drive there"
            ) from None
        raise
    if output is not None:
        write_file_atomic(output, result.document)
    if not run:
        return Planned(result, what)
    sim = SimOptions(message=result.document.decode("utf-8"))
    return Planned(result, what, execute(robot_file, sim, robot.packages))
