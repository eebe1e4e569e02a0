"""`armcli check`: lint URDFs (or specs, built in memory) for physical sanity."""

from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from armcli.commands.options import choice
from armcli.commands.robot_input import robot_options, write_notes
from armcli.commands.values import REACH_POINT_HELP, Names, Numbers, names, point
from armcli.defaults import ROS_DISTROS
from armcli.errors import (
    EXIT_FAILED,
    EXIT_UNUSABLE,
    EXPANDED_TAG,
    FindingsError,
    InputError,
    UnusableInputsError,
)
from armcli.io import terminal

if TYPE_CHECKING:  # the checker is imported when the command runs: `--help` stays light
    from armcli.check.inputs import CheckRun
    from armcli.check.options import TipoverOptions
    from armcli.urdf.source import RobotInput

FORMATS = ("table", "json", "github", "sarif")
PAYLOAD_LINK_HELP = "Link carrying --payload at its origin (default: the tool point)."
CONTACT_LINKS_HELP = "Comma-separated links touching the ground (default: from the geometry)."
TRAJECTORY_HELP = "Simulate this JointTrajectory and report the zero-moment point (needs gains)."
DISTRO_HELP = (
    "ROS 2 distro of a directory of ROS packages: humble, jazzy, kilted or lyrical "
    "(default: from the Gazebo plugins and packages found)."
)
BASE_ACCEL_HELP = (
    "Base acceleration and braking [m/s²] with --trajectory "
    "(default: the diff-drive plugin's max_wheel_acceleration)."
)


def tipover_options(
    payload: float,
    payload_link: str | None,
    contact_links: Names | None,
    min_margin: float,
    trajectory: Path | None,
    base_accel: float | None,
    reach_points: list[Numbers],
) -> TipoverOptions:
    """The balance and reach options, refused here when they are not usable numbers."""
    from armcli.check.options import TipoverOptions

    for flag, x in (("--payload", payload), ("--min-margin", min_margin),
                    ("--base-accel", 0.0 if base_accel is None else base_accel)):  # fmt: skip
        if not (math.isfinite(x) and x >= 0):
            raise InputError(f"must be a finite number >= 0, got {x:g}", field=flag)
    if trajectory is not None and not trajectory.is_file():
        raise InputError("no such file", file=trajectory, field="--trajectory")
    return TipoverOptions(
        payload=payload,
        payload_link=payload_link,
        contact_links=contact_links,
        min_margin=min_margin,
        trajectory=trajectory,
        base_accel=base_accel,
        reach_points=tuple((p[0], p[1], p[2]) for p in reach_points),
    )


@robot_options("paths")
def check_cmd(
    robot: RobotInput,
    spec: Path | None = typer.Option(
        None, "--spec", help="Spec to compare limits with; also gives gains, dt, poses, tool."
    ),
    fmt: str = choice("table", FORMATS, "--format", help="Report format (default: table)."),
    strict: bool = typer.Option(False, "--strict", help="Treat warnings as errors."),
    ignore: list[str] = typer.Option([], "--ignore", help="Silence a rule id (repeatable)."),
    payload: float = typer.Option(0.0, "--payload", help="Payload [kg] at the tool point."),
    payload_link: str = typer.Option(None, "--payload-link", help=PAYLOAD_LINK_HELP),
    contact_links: Names = typer.Option(
        None, "--contact-links", parser=names, metavar="LINK,...", help=CONTACT_LINKS_HELP
    ),
    min_margin: float = typer.Option(
        0.02, "--min-margin", help="Balance margin [m] below which to warn."
    ),
    trajectory: Path = typer.Option(None, "--trajectory", "-t", help=TRAJECTORY_HELP),
    base_accel: float = typer.Option(None, "--base-accel", help=BASE_ACCEL_HELP),
    reach_point: list[Numbers] = typer.Option(
        [], "--reach-point", parser=point("--reach-point"), metavar="X,Y,Z", help=REACH_POINT_HELP
    ),
    distro: str = choice(None, ROS_DISTROS, "--distro", help=DISTRO_HELP),
) -> None:
    """Check robot descriptions for physical sanity; exit 1 on error findings."""
    from armcli.check import report
    from armcli.check.findings import apply_policy
    from armcli.check.inputs import run_check
    from armcli.check.options import CheckOptions
    from armcli.check.report import counts
    from armcli.check.rules import RULES, unknown_rules

    unknown = unknown_rules(ignore)
    if unknown:
        raise InputError(f"unknown rule(s) {unknown}; known: {', '.join(RULES)}", field="--ignore")
    tip = tipover_options(
        payload, payload_link, contact_links, min_margin, trajectory, base_accel, reach_point
    )
    base = CheckOptions(package_dirs=robot.packages.package_dirs, tipover=tip, ros_distro=distro)
    if spec is not None:  # the spec layers (pydantic, ~0.4 s to import) only for a spec
        from armcli.spec.load import load_spec

        base = replace(base, spec=load_spec(spec))
    run = run_check(robot.files(), base, trust_xacro=robot.trust, inputs=robot.xacro)
    for file, note in run.notes:
        write_notes([note], file.removesuffix(EXPANDED_TAG))
    everything = [f for r in run.results for f in r.findings]
    everything += [u.finding() for u in run.unusable]
    findings = report.by_severity(apply_policy(everything, ignore=ignore, strict=strict))
    code = run.exit_code(findings)
    _print(run, findings, fmt, code)
    if code == EXIT_UNUSABLE:
        raise UnusableInputsError([u.error for u in run.unusable])
    if code == EXIT_FAILED:
        n_err = counts(findings)["error"]
        raise FindingsError(
            f"{n_err} error finding(s) in {len(run.results) + len(run.unusable)} file(s)",
            [u.error for u in run.unusable],
        )


def _print(run: CheckRun, findings: list[Any], fmt: str, code: int) -> None:
    from armcli.check import report
    from armcli.check.sarif import to_sarif

    unusable = [(u.file, u.error.message) for u in run.unusable]
    if fmt == "json":
        sys.stdout.write(report.to_json(run.results, findings, code, unusable))
    elif fmt == "github":
        sys.stdout.write(report.to_github(findings))
    elif fmt == "sarif":
        sys.stdout.write(to_sarif(findings))
    elif run.results:  # nothing usable: the stderr lines say it all
        console = terminal.console()
        for item in report.to_rich(run.results, findings, [u for u, _ in unusable]):
            console.print(item, crop=False)


def register(app: typer.Typer) -> None:
    """Add the `check` command to the typer app."""
    app.command("check")(check_cmd)
