"""`ros-classic-plugin`: a Gazebo plugin the simulator the launch starts does not load.

Gazebo classic loads `lib*.so` model plugins (gazebo_plugins' `libgazebo_ros_*.so`,
`libgazebo_ros2_control.so`); Gazebo Harmonic (and Fortress) load systems
(`gz-sim-*-system`, `ignition-gazebo-*-system`, `gz_ros2_control-system`). Each ignores
the other's `<plugin>` without an error: the robot spawns but its joints publish
nothing, the base does not drive, the controllers never appear. Judged per launch run,
for the robot descriptions it loads and the simulator it starts (launches.py), and
against the distro: Humble's Fortress knows only the `ign` names, Jazzy's Harmonic and
later only `gz_ros2_control`, and Gazebo classic is not released after Humble.
"""

from __future__ import annotations

from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.launches import CLASSIC, GZ, Run
from armcli.urdf.doc import Urdf

RULE = "ros-classic-plugin"
GZ_MARKERS = (
    "gz-sim",
    "ignition-gazebo",
    "gz_ros2_control",
    "ign_ros2_control",
    "gz::sim",
    "ignition::gazebo",
)
CLASSIC_HARDWARE = "gazebo_ros2_control/GazeboSystem"
GZ_HARDWARE = ("gz_ros2_control/GazeboSimSystem", "ign_ros2_control/IgnitionSystem")
NAMES = {CLASSIC: "Gazebo classic", GZ: "Gazebo (gz sim)"}


def family(filename: str, name: str = "") -> str | None:
    """CLASSIC, GZ or None (not a Gazebo plugin) for a `<plugin filename name>`."""
    base = filename.rsplit("/", 1)[-1]
    if any(m in base or m in name for m in GZ_MARKERS):
        return GZ
    if base.startswith("lib") and base.endswith(".so") and "gazebo" in base:
        return CLASSIC
    return None


def check(ctx: PackageContext) -> None:
    """Per run that starts a simulator: every plugin of its descriptions of the other kind."""
    seen: set[tuple[str, int | None]] = set()
    for run in ctx.runs:
        if not run.sims:
            continue
        if CLASSIC in run.sims and not ctx.distro.classic:
            where = run.sims[CLASSIC]
            if (where.file, where.line) not in seen:
                seen.add((where.file, where.line))
                ctx.add(
                    RULE,
                    where.file,
                    where.line,
                    f"{run.root.name} starts Gazebo classic (gazebo_ros), which is not "
                    f"released for ROS 2 {ctx.distro.name}: use ros_gz_sim (Gazebo "
                    "Harmonic) and its plugins",
                    {},
                    simulator=CLASSIC,
                )
        for urdf in ctx.urdfs(run.descriptions):
            _plugins(ctx, run, urdf, seen)


def _plugins(ctx: PackageContext, run: Run, urdf: Urdf, seen: set[tuple[str, int | None]]) -> None:
    started = set(run.sims)
    for plug in urdf.plugins:
        kind = family(plug.filename or "", plug.name or "")
        key = (urdf.source, plug.line)
        if kind is None or key in seen:
            continue
        why = _why(ctx, started, kind, plug.filename or "")
        if why is not None:
            seen.add(key)
            ctx.add_in(
                RULE,
                urdf,
                plug.line,
                f"plugin {plug.filename!r} is for {NAMES[kind]}, but {run.root.name} "
                f"{why}: it is silently not loaded",
                {},
                plugin=plug.filename,
            )
    for rc in urdf.ros2_control:
        kind = (
            CLASSIC
            if rc.hardware == CLASSIC_HARDWARE
            else (GZ if rc.hardware in GZ_HARDWARE else None)
        )
        key = (urdf.source, rc.line)
        why = _why(ctx, started, kind, rc.hardware) if kind else None
        if why is not None and key not in seen:
            seen.add(key)
            ctx.add_in(
                RULE,
                urdf,
                rc.line,
                f"<ros2_control> hardware {rc.hardware!r} is for {NAMES[kind or GZ]}, but "
                f"{run.root.name} {why}: the controllers never start",
                {},
                plugin=rc.hardware,
            )


def _why(ctx: PackageContext, started: set[str], kind: str | None, name: str) -> str | None:
    """Why a plugin of `kind` does not load in this run, or None when it does."""
    if kind is None:
        return None
    if kind not in started:
        other = NAMES[GZ if kind == CLASSIC else CLASSIC]
        return f"starts {other}"
    if kind == GZ:
        gz_name = any(m in name for m in ("gz-sim", "gz_ros2_control", "GazeboSimSystem"))
        if ctx.distro.gz_prefix == "ign" and gz_name:
            return f"runs on {ctx.distro.name}, whose Gazebo (Fortress) knows the ign_ names"
        if ctx.distro.gz_prefix == "gz" and "ign_ros2_control-system" in name:
            return (
                f"runs on {ctx.distro.name}, where gz_ros2_control has no "
                "ign_ros2_control-system library (use gz_ros2_control-system)"
            )
    return None
