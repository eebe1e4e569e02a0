"""`armcli check`: lint URDFs (or specs, built in memory) for physical sanity."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.options import choice
from armcli.commands.robot_input import robot_options, write_notes
from armcli.commands.values import REACH_POINT_HELP, Names, Numbers, names, point
from armcli.defaults import ROS_DISTROS
from armcli.errors import (
    EXPANDED_TAG,
)
from armcli.io import terminal

if TYPE_CHECKING:  # the checker is imported when the command runs: `--help` stays light
    from armcli.check.inputs import CheckRun
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


# The library's names for what these flags set (errors name them; commands.flags maps back).
FLAGS = {
    "ignore": "--ignore",
    "TipoverOptions.payload": "--payload",
    "TipoverOptions.min_margin": "--min-margin",
    "TipoverOptions.base_accel": "--base-accel",
    "TipoverOptions.trajectory": "--trajectory",
}


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
    from armcli.check.api import check
    from armcli.check.options import CheckOptions, TipoverOptions

    reach = tuple((p[0], p[1], p[2]) for p in reach_point)
    tip = TipoverOptions(
        payload, payload_link, contact_links, min_margin, trajectory, base_accel, reach
    )
    base = CheckOptions(package_dirs=robot.packages.package_dirs, tipover=tip, ros_distro=distro)
    with flag_errors(FLAGS):
        checked = check(
            robot.files(),
            base,
            spec=spec,
            ignore=ignore,
            strict=strict,
            trust_xacro=robot.trust,
            inputs=robot.xacro,
        )
    for file, note in checked.run.notes:
        write_notes([note], file.removesuffix(EXPANDED_TAG))
    _print(checked.run, checked.findings, fmt, checked.code)
    error = checked.error()
    if error is not None:
        raise error


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
            console.print(terminal.fitted(item), crop=False)


def register(app: typer.Typer) -> None:
    """Add the `check` command to the typer app."""
    app.command("check")(check_cmd)
