"""`ros-joint-states-twice`: more than one publisher of `/joint_states` in one launch.

robot_state_publisher turns `/joint_states` into TF; with two publishers (the
joint_state_publisher GUI's sliders at their zeros beside Gazebo's joint-state plugin or a
joint_state_broadcaster) the two streams alternate and the arm flickers in RViz. Counted
per launch run (includes and MoveIt generators merged), only what certainly starts:
joint_state_publisher[_gui] nodes, spawners (or `ros2 control load_controller`) of
a joint_state_broadcaster, Gazebo classic's `libgazebo_ros_joint_state_publisher.so`
in a robot description the launch loads into the Gazebo it starts, and a ros_gz_bridge
bringing Gazebo's joint states to `/joint_states`. A publisher remapped
or namespaced away from `/joint_states` does not count. The finding is on the publisher to remove: a
joint_state_publisher node first (the simulator or ros2_control knows the real state).
"""

from __future__ import annotations

from dataclasses import dataclass

from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.launch_model import Node, Where
from armcli.check.ros_packages.launches import CLASSIC, Run
from armcli.check.ros_packages.params import JSB
from armcli.urdf.doc import Urdf

RULE = "ros-joint-states-twice"
TOPIC = "/joint_states"
GUI_PACKAGES = ("joint_state_publisher", "joint_state_publisher_gui")
SPAWNERS = ("spawner", "spawner.py", "load_controller")
PLUGIN = "libgazebo_ros_joint_state_publisher.so"
BRIDGES = ("ros_gz_bridge", "ros_ign_bridge")
BROADCASTER_NAMES = ("joint_state_broadcaster", "joint_state_controller")


@dataclass(frozen=True)
class Publisher:
    """One source of /joint_states in a launch: what it is, where it is started."""

    what: str
    where: Where
    rank: int  # which to remove first: 0 a joint_state_publisher node, 1 a plugin, 2 a spawner
    urdf: Urdf | None = None  # a plugin's description
    line: int | None = None  # the plugin's line in it


def check(ctx: PackageContext) -> None:
    """One finding per extra publisher, on the one to remove."""
    for run in ctx.runs:
        pubs = publishers(ctx, run)
        if len(pubs) < 2:
            continue
        pubs.sort(key=lambda p: p.rank)
        keep = pubs[-1]
        for extra in pubs[:-1]:
            others = ", ".join(f"{p.what} ({_at(p.where)})" for p in pubs if p is not extra)
            msg = (
                f"{TOPIC} has {len(pubs)} publishers when {run.root.name} runs: {extra.what} "
                f"and {others}; robot_state_publisher takes both and RViz flickers between "
                f"them (keep {keep.what})"
            )
            if extra.urdf is not None:
                ctx.add_in(RULE, extra.urdf, extra.line, msg, {}, publisher=extra.what)
            else:
                ctx.add(RULE, extra.where.file, extra.where.line, msg, {}, publisher=extra.what)


def _at(where: Where) -> str:
    return f"{where.file.rsplit('/', 1)[-1]}:{where.line}" if where.line else where.file


def publishers(ctx: PackageContext, run: Run) -> list[Publisher]:
    """Every certain publisher of /joint_states in a run."""
    out: list[Publisher] = []
    broadcasters = _broadcasters(ctx, run)
    seen: set[str] = set()
    for n in run.nodes:
        if n.active is not True:
            continue
        if n.package in GUI_PACKAGES and _topic(n) == TOPIC:
            out.append(Publisher(n.executable or n.package or "joint_state_publisher", n.where, 0))
        elif n.package == "controller_manager" and n.executable in SPAWNERS:
            for c in (a for a in n.arguments if a and a in broadcasters and a not in seen):
                seen.add(c)
                out.append(Publisher(f"the {c} spawner", n.where, 2))
        elif n.package in BRIDGES and _bridges_joint_states(ctx, n):
            out.append(Publisher("ros_gz_bridge's /joint_states from Gazebo", n.where, 1))
    for p in run.processes:
        tokens = [t for t in p.cmd if t]
        if "load_controller" in tokens:
            for c in (t for t in tokens if t in broadcasters and t not in seen):
                seen.add(c)
                out.append(Publisher(f"{c} (ros2 control load_controller)", p.where, 2))
    for u in ctx.urdfs(run.descriptions) if CLASSIC in run.sims else ():  # only when it runs
        for plug in u.plugins:
            if (plug.filename or "").rsplit("/", 1)[-1] == PLUGIN:
                origin = u.origins.get(plug.line) if plug.line else None
                where = Where(origin.file, origin.line) if origin else Where(u.source, plug.line)
                out.append(
                    Publisher("Gazebo's joint_state_publisher plugin", where, 1, u, plug.line)
                )
    return out


def _bridges_joint_states(ctx: PackageContext, n: Node) -> bool:
    """Whether a ros_gz_bridge node brings Gazebo's joint states to /joint_states.

    By an argument `/joint_states@sensor_msgs/msg/JointState[gz.msgs.Model` (`[` or `@`:
    Gazebo to ROS) or an entry of its `config_file` (direction GZ_TO_ROS or BIDIRECTIONAL).
    """
    for a in n.arguments:
        topic, sep, rest = (a or "").partition("@")
        if sep and topic.lstrip("/") == TOPIC[1:] and ("[" in rest or "@" in rest):
            return True
    config = n.params.get("config_file")
    local = ctx.local(config) if isinstance(config, str) else None
    doc = ctx.yaml(local) if local is not None else None
    entries = doc.data if doc is not None and isinstance(doc.data, list) else []
    return any(
        isinstance(e, dict)
        and str(e.get("ros_topic_name", "")).lstrip("/") == TOPIC[1:]
        and e.get("direction", "BIDIRECTIONAL") in ("GZ_TO_ROS", "BIDIRECTIONAL")
        for e in entries
    )


def _topic(n: Node) -> str:
    """Where a joint_state_publisher node publishes, after namespace and remapping."""
    topic = "joint_states"
    for src, dst in n.remappings:
        if src in ("joint_states", "/joint_states", "~/joint_states") and dst:
            topic = dst
    if topic.startswith("/"):
        return topic
    ns = (n.namespace or "").strip("/")
    return f"/{ns}/{topic}" if ns else f"/{topic}"


def _broadcasters(ctx: PackageContext, run: Run) -> set[str]:
    """Controller names that are joint_state_broadcasters in this run's controllers files.

    Also, where no file says, by their conventional names.
    """
    names = set(BROADCASTER_NAMES)
    files = ctx.run_controllers(run) or ctx.all_controller_files()
    for f in files:
        cf = ctx.controllers(f)
        if cf is not None:
            names |= {c.name for c in cf.controllers.values() if c.type == JSB}
    return names
