"""`ros-control-node-with-sim`: `ros2_control_node` beside a simulator's controller manager.

The robot's `<ros2_control>` hardware is a simulator's system.

gz_ros2_control (`gz_ros2_control/GazeboSimSystem`, Humble's `ign_ros2_control/
IgnitionSystem`) and gazebo_ros2_control (`gazebo_ros2_control/GazeboSystem`) run their
own controller manager inside the simulator's plugin. A second one from
`ros2_control_node` cannot load that hardware outside Gazebo (or, with a namespace
mix-up, takes the controllers' names): spawners time out or talk to the wrong manager.
The robot is the one the node is given (`robot_description`) or, as from Jazzy on,
the descriptions its launch loads; a MoveIt `generate_demo_launch` starts one too.
"""

from __future__ import annotations

from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.launch_model import Node
from armcli.check.ros_packages.launches import Run
from armcli.urdf.doc import Urdf

RULE = "ros-control-node-with-sim"
SIM_SYSTEMS = (
    "gz_ros2_control/GazeboSimSystem",
    "ign_ros2_control/IgnitionSystem",
    "gazebo_ros2_control/GazeboSystem",
)


def check(ctx: PackageContext) -> None:
    """One finding per ros2_control_node whose robot's hardware is a simulator's."""
    seen: set[tuple[str, int | None]] = set()
    for run in ctx.runs:
        for node in run.nodes:
            if not _is_control_node(node) or node.active is not True:
                continue
            key = (node.where.file, node.where.line)
            if key in seen:
                continue
            for urdf in _robots(ctx, run, node):
                system = next((rc for rc in urdf.ros2_control if rc.hardware in SIM_SYSTEMS), None)
                if system is None:
                    continue
                seen.add(key)
                what = (
                    "MoveIt's generate_demo_launch starts ros2_control_node"
                    if node.implied_by
                    else "ros2_control_node is started here"
                )
                ctx.add(
                    RULE,
                    node.where.file,
                    node.where.line,
                    f"{what} for {urdf.name!r}, whose <ros2_control> {system.name!r} uses "
                    f"{system.hardware}: that plugin runs its own controller manager inside "
                    "Gazebo, and a second one cannot drive the simulated joints",
                    {},
                    hardware=system.hardware,
                )
                break


def _is_control_node(node: Node) -> bool:
    return node.package == "controller_manager" and node.executable == "ros2_control_node"


def _robots(ctx: PackageContext, run: Run, node: Node) -> list[Urdf]:
    if node.description is not None:
        own = ctx.urdf(node.description)
        if own is not None:
            return [own]
    return ctx.urdfs(run.descriptions)
