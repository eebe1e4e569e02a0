"""`ros-missing-depend`: launch files using a package package.xml does not depend on.

`rosdep install --from-paths src` and binary releases install only what package.xml
declares; a launch file that starts `robot_state_publisher`, includes `ros_gz_sim`'s
launch, runs `xacro` or imports `launch_ros` then fails on a fresh machine with "package
not found". Used are: node packages, the packages of included launch files and of
`$(find-pkg-share)` / `get_package_share_directory` / `FindPackageShare`, `xacro` for a
xacro command, and the ROS Python modules a launch file imports (not launch, launch_ros
and ament_index_python: `ros2 launch` itself needs them). Any of `depend`,
`exec_depend`, `build_export_depend` (or format 1's `run_depend`) satisfies it, and so
does a metapackage that lists it (`gazebo_ros_pkgs`, `ros2_control`, `ros2_controllers`). The
finding is on package.xml, where the dependency goes.
"""

from __future__ import annotations

from pathlib import Path

from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.launch_model import LaunchDoc, split_package_uri
from armcli.check.ros_packages.launches import launch_files

RULE = "ros-missing-depend"
# Python modules a launch file imports -> the ROS package that provides them. launch,
# launch_ros and ament_index_python are not listed: `ros2 launch` (ros2launch) depends on
# them, so wherever a launch file can run they are installed.
MODULE_PACKAGES = {
    "moveit_configs_utils": "moveit_configs_utils",
    "xacro": "xacro",
    "launch_param_builder": "launch_param_builder",
    "nav2_common": "nav2_common",
}
# Metapackages (their package.xml's exec_depends, Humble to Rolling): depending on one
# brings what it lists, which a launch file then uses.
METAPACKAGES = {
    "gazebo_ros_pkgs": ("gazebo_dev", "gazebo_msgs", "gazebo_plugins", "gazebo_ros"),
    "ros2_control": (
        "controller_interface",
        "controller_manager",
        "hardware_interface",
        "joint_limits",
        "ros2controlcli",
        "transmission_interface",
    ),
    "ros2_controllers": (
        "admittance_controller",
        "diff_drive_controller",
        "effort_controllers",
        "force_torque_sensor_broadcaster",
        "forward_command_controller",
        "gripper_controllers",
        "imu_sensor_broadcaster",
        "joint_state_broadcaster",
        "joint_trajectory_controller",
        "position_controllers",
        "tricycle_controller",
        "velocity_controllers",
    ),
    "ros_gz": ("ros_gz_bridge", "ros_gz_image", "ros_gz_interfaces", "ros_gz_sim"),
    "moveit": (
        "moveit_core",
        "moveit_planners",
        "moveit_plugins",
        "moveit_ros",
        "moveit_setup_assistant",
        "moveit_ros_move_group",
        "moveit_ros_visualization",
        "moveit_simple_controller_manager",
    ),
}
ALWAYS_THERE = frozenset(
    {"launch", "launch_ros", "launch_xml", "launch_yaml", "ament_index_python"}
)


def check(ctx: PackageContext) -> None:
    """Per package: each package its launch files use and it does not depend on, once."""
    for pkg in ctx.ws.packages.values():
        needs: dict[str, tuple[Path, int | None]] = {}
        for path in launch_files(pkg):
            doc = _doc(ctx, path)
            if doc is not None:
                for name, line in used(ctx, doc).items():
                    needs.setdefault(name, (path, line))
        have = {*pkg.depends, *(m for d in pkg.depends for m in METAPACKAGES.get(d, ()))}
        for name, (path, line) in sorted(needs.items()):
            if name == pkg.name or name in have or name in ALWAYS_THERE:
                continue
            rel = path.relative_to(pkg.root)
            ctx.add(
                RULE,
                pkg.manifest,
                pkg.insert_line,
                f"{pkg.name}: {rel}:{line} uses {name}, which package.xml does not depend on: "
                f"rosdep and binary installs leave it out (add <exec_depend>{name}"
                "</exec_depend>)",
                {"exec_depend": name},
                package=name,
            )


def _doc(ctx: PackageContext, path: Path) -> LaunchDoc | None:
    """The launch file as read with its defaults (the runs' cache)."""
    return next((r.docs[0] for r in ctx.runs if r.root == path), None)


def used(ctx: PackageContext, doc: LaunchDoc) -> dict[str, int | None]:
    """Package -> first line, of everything a launch document uses."""
    out: dict[str, int | None] = {}
    for module, line in doc.imports.items():
        if module in MODULE_PACKAGES:
            out.setdefault(MODULE_PACKAGES[module], line)
    for package, line in doc.uses.items():
        out.setdefault(package, line)
    for n in doc.nodes:
        if n.package and not n.implied_by:
            out.setdefault(n.package, n.where.line)
    for inc in doc.includes:
        uri = split_package_uri(inc.target or "")
        owner = ctx.ws.owner(Path(inc.target)) if inc.target and uri is None else None
        name = uri[0] if uri else (owner.name if owner else None)
        if name:
            out.setdefault(name, inc.where.line)
    for d in doc.descriptions:
        if d.where is not None and not d.file.endswith(".urdf"):
            out.setdefault("xacro", d.where.line)
    return out
