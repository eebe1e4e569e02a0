"""`armcli ros-package`: write the description, bringup and MoveIt config packages."""

from __future__ import annotations

import sys
from pathlib import Path

import click
import typer

from armcli.build.expand import spec_label
from armcli.defaults import DEFAULT_SPEC
from armcli.ros.packages import DEFAULT_TARGET, TARGETS, PackageInfo, write_ros_packages

DEFAULT_SAMPLES = 10_000  # keep equal to armcli.ros.collision_matrix.DEFAULT_SAMPLES (lazy import)
MAX_SAMPLES = 1_000_000  # ~100x the default: minutes of coal queries, not days


def ros_package_cmd(
    spec: Path = typer.Argument(
        DEFAULT_SPEC, show_default=False, help=f"Robot spec YAML (default: {DEFAULT_SPEC})."
    ),
    out: Path = typer.Option(
        Path("ros"), "-o", "--out", show_default=False, help="Output directory (default: ros)."
    ),
    samples: int = typer.Option(
        DEFAULT_SAMPLES,
        "--samples",
        min=1,
        max=MAX_SAMPLES,
        show_default=False,
        help=f"Random states for the collision matrix (default: {DEFAULT_SAMPLES}).",
    ),
    seed: int = typer.Option(
        0,
        "--seed",
        min=0,
        max=2**32 - 1,
        show_default=False,
        help="Seed of the collision-matrix sampling (default: 0).",
    ),
    maintainer: str = typer.Option(
        "armcli",
        "--maintainer",
        show_default=False,
        help="package.xml maintainer (default: armcli).",
    ),
    email: str = typer.Option(
        "armcli@example.com",
        "--email",
        show_default=False,
        help="Maintainer e-mail (default: armcli@example.com).",
    ),
    license_: str = typer.Option(
        "TODO", "--license", show_default=False, help="package.xml license (default: TODO)."
    ),
    target: str = typer.Option(
        DEFAULT_TARGET,
        "--target",
        click_type=click.Choice(TARGETS),
        show_default=False,
        help="humble-classic: the course's ROS 2 Humble + Gazebo classic (default); "
        "jazzy: ROS 2 Jazzy + Gazebo Harmonic with ros2_control (effort, the spec's gains).",
    ),
    force: bool = typer.Option(
        False, "--force", help="Write into an existing non-empty directory armcli did not create."
    ),
) -> None:
    """Write ROS 2 packages for SPEC: <name>_description, <name>_bringup, <name>_moveit_config."""
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
    )
    n, m = pkgs.names, pkgs.matrix
    counts = {r: sum(d.reason == r for d in m.disabled) for r in ("Adjacent", "Default", "Never")}
    w = sys.stdout.write
    w(f"wrote {len(written)} files into {out}/: {n.description}, {n.bringup}, {n.moveit}\n")
    w(
        f"collision matrix ({m.samples} samples, seed {m.seed}): {len(m.links)} links, "
        f"disabled {counts['Adjacent']} Adjacent, {counts['Default']} Default, "
        f"{counts['Never']} Never; {len(m.enabled)} pair(s) still checked\n"
    )
    for p in m.enabled:
        w(f"  checked: {p.link1} / {p.link2} (in collision in {p.collisions} of {m.samples})\n")
    for pose, a, b in m.pose_collisions:
        sys.stderr.write(
            f"warning: named pose {pose!r} puts {a} and {b} in contact; "
            "MoveIt will report that state as in collision\n"
        )


def register(app: typer.Typer) -> None:
    """Add the `ros-package` command to the typer app."""
    app.command("ros-package")(ros_package_cmd)
