"""`armcli ros-package`: write the description, bringup and MoveIt config packages."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.options import choice, option, out_option, seed_option
from armcli.commands.robot_input import robot_options
from armcli.defaults import COLLISION_SAMPLES, ROS_TARGETS
from armcli.io.terminal import say

if TYPE_CHECKING:
    from armcli.ros.packages import RosPackages
    from armcli.urdf.source import RobotInput

TARGET_HELP = (
    "humble-classic: the course's ROS 2 Humble + Gazebo classic (default); jazzy: ROS 2 Jazzy "
    "+ Gazebo Harmonic with ros2_control (effort, the spec's gains)."
)
MAX_SAMPLES = 1_000_000  # ~100x the default: minutes of coal queries, not days


@flag_errors({"out_dir": "--out"})  # the library names its parameter
@robot_options("spec", xacro=False)
def ros_package_cmd(
    robot: RobotInput,
    out: Path = out_option(Path("ros"), "Output directory"),
    samples: int = option(
        COLLISION_SAMPLES,
        "--samples",
        min=1,
        max=MAX_SAMPLES,
        help="Random states for the collision matrix",
    ),
    seed: int = seed_option("Seed of the collision-matrix sampling"),
    maintainer: str = option("armcli", "--maintainer", help="package.xml maintainer"),
    email: str = option("armcli@example.com", "--email", help="Maintainer e-mail"),
    license_: str = option("TODO", "--license", help="package.xml license"),
    target: str = choice(ROS_TARGETS[0], ROS_TARGETS, "--target", help=TARGET_HELP),
    force: bool = option(
        False, "--force", help="Write into an existing non-empty directory armcli did not create."
    ),
) -> None:
    """Write ROS 2 packages for SPEC: <name>_description, <name>_bringup, <name>_moveit_config."""
    from armcli.compiler.expand import spec_label  # on use: `--help` stays light
    from armcli.ros.packages import PackageInfo, write_ros_packages

    spec = robot.file()
    info = PackageInfo(maintainer=maintainer, email=email, license=license_)
    pkgs, written = write_ros_packages(
        spec,
        out,
        label=spec_label(spec),
        samples=samples,
        seed=seed,
        info=info,
        target=target,
        force=force,
        packages=robot.packages,
    )
    _print(pkgs, len(written), out)


def _print(pkgs: RosPackages, written: int, out: Path) -> None:
    """What was written, the collision matrix in numbers, and the poses MoveIt will refuse."""
    n, m = pkgs.names, pkgs.matrix
    counts = {r: sum(d.reason == r for d in m.disabled) for r in ("Adjacent", "Default", "Never")}
    say(f"wrote {written} files into {out}/: {n.description}, {n.bringup}, {n.moveit}")
    say(
        f"collision matrix ({m.samples} samples, seed {m.seed}): {len(m.links)} links, "
        f"disabled {counts['Adjacent']} Adjacent, {counts['Default']} Default, "
        f"{counts['Never']} Never; {len(m.enabled)} pair(s) still checked"
    )
    for p in m.enabled:
        say(f"  checked: {p.link1} / {p.link2} (in collision in {p.collisions} of {m.samples})")
    for pose, a, b in m.pose_collisions:
        say(
            f"warning: named pose {pose!r} puts {a} and {b} in contact; "
            "MoveIt will report that state as in collision",
            sys.stderr,
        )


def register(app: typer.Typer) -> None:
    """Add the `ros-package` command to the typer app."""
    app.command("ros-package")(ros_package_cmd)
