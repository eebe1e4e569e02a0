"""`ros-sim-time`: a node of a launch that starts a simulator without `use_sim_time: true`.

Gazebo publishes its own `/clock`; a node left on wall-clock time stamps TF and messages
hours away from the simulation's, so RViz drops transforms as too old, MoveIt waits for a
current robot state and TF lookups time out. Decided per node from what the launch
states: its inline parameters, its parameter files (`ros__parameters` for its name or
`/**`), a `SetParameter` of the launch, in that order; a value the launch computes is not
judged. Nodes that do not stamp anything are left out (spawners, the bridge, static TF).
"""

from __future__ import annotations

from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.launch_model import UNKNOWN, Node, truthy
from armcli.check.ros_packages.launches import Run
from armcli.check.ros_packages.params import node_params

RULE = "ros-sim-time"
KEY = "use_sim_time"
EXEMPT = {  # (package, executable): nodes whose clock does not matter
    ("controller_manager", "spawner"),
    ("controller_manager", "spawner.py"),
    ("controller_manager", "unspawner"),
    ("gazebo_ros", "spawn_entity.py"),
    ("ros_gz_sim", "create"),
    ("ros_ign_gazebo", "create"),
    ("ros_gz_bridge", "parameter_bridge"),
    ("ros_ign_bridge", "parameter_bridge"),
    ("ros_gz_image", "image_bridge"),
    ("tf2_ros", "static_transform_publisher"),
    ("gazebo_ros", "gzserver"),
    ("gazebo_ros", "gzclient"),
    ("controller_manager", "ros2_control_node"),  # reported by ros-control-node-with-sim
}


def check(ctx: PackageContext) -> None:
    """One warning per node (at its line) of every run that starts Gazebo."""
    seen: set[tuple[str, int | None, str]] = set()
    for run in ctx.runs:
        if not run.sims:
            continue
        sim = next(iter(run.sims.values()))
        for node in run.nodes:
            if node.active is not True or (node.package, node.executable) in EXEMPT:
                continue
            value = _value(ctx, run, node)
            if value is UNKNOWN or truthy(value) is True:
                continue
            key = (node.where.file, node.where.line, node.label)
            if key in seen:
                continue
            seen.add(key)
            said = "use_sim_time is false" if truthy(value) is False else "use_sim_time is not set"
            file, line = node.where.file, node.param_lines.get(KEY, node.where.line)
            inc = run.included.get(node.where.file)
            if inc is not None and truthy(inc.args.get(KEY)) is False:  # the includer's value
                file, line = inc.where.file, inc.where.line
                said = f"use_sim_time is false, passed by the include at line {line}"
            started = f"{sim.file.rsplit('/', 1)[-1]}:{sim.line}"
            via = f" (started by MoveIt's {node.implied_by})" if node.implied_by else ""
            via += (
                f" ({_short(node.where.file)}:{node.where.line})" if file != node.where.file else ""
            )
            ctx.add(
                RULE,
                file,
                line,
                f"{node.label}{via}: {said} while {run.root.name} starts Gazebo "
                f"({started}), whose /clock it then ignores: its timestamps are wall-clock "
                "time and TF and RViz drop the simulation's messages as too old",
                {KEY: "true"},
                node=node.label,
            )


def _short(path: str) -> str:
    return path.rsplit("/", 1)[-1]


def _value(ctx: PackageContext, run: Run, node: Node) -> object:
    """use_sim_time as the node gets it, None when nothing sets it, UNKNOWN if computed."""
    if KEY in node.params:
        return node.params[KEY]
    for f in reversed(node.param_files):  # a later file overrides an earlier one
        local = ctx.local(f)
        doc = ctx.yaml(local) if local is not None else None
        if local is None:
            return UNKNOWN  # a file outside DIR: not known
        if doc is not None:
            params = node_params(doc, node.name or node.executable)
            if KEY in params:
                return params[KEY]
    if node.unknown_params:
        return UNKNOWN
    return run.global_params.get(KEY)
