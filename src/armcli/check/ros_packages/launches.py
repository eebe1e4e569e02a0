"""Every launch file of the packages as a run: the file plus what it includes, and what starts.

Any launch file may be what a user types after `ros2 launch`, so each one is a run, read
with its own defaults; its includes are followed (with the arguments passed, literal ones)
into files under DIR, and recognised when they are another package's: Gazebo classic
(gazebo_ros), Gazebo Harmonic/Fortress (ros_gz_sim, ros_ign_gazebo). A MoveIt launch
generator (`generate_demo_launch`, ...) stands for the nodes it starts (`implied`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from armcli.check.ros_packages.files import Problem
from armcli.check.ros_packages.launch_model import (
    Description,
    Include,
    LaunchDoc,
    MoveItLaunch,
    Node,
    Process,
    Where,
    split_package_uri,
)
from armcli.check.ros_packages.launch_py import read_python_launch
from armcli.check.ros_packages.launch_xml import read_xml_launch
from armcli.check.ros_packages.substitute import Shares
from armcli.check.ros_packages.workspace import Package, Workspace
from armcli.errors import InputError

CLASSIC, GZ = "classic", "gz"  # the two Gazebo families a launch may start
SIM_INCLUDES = {
    ("gazebo_ros", "gazebo.launch.py"): CLASSIC,
    ("gazebo_ros", "gzserver.launch.py"): CLASSIC,
    ("ros_gz_sim", "gz_sim.launch.py"): GZ,
    ("ros_ign_gazebo", "ign_gazebo.launch.py"): GZ,
}
SIM_NODES = {
    ("gazebo_ros", "spawn_entity.py"): CLASSIC,
    ("gazebo_ros", "gzserver"): CLASSIC,
    ("ros_gz_sim", "create"): GZ,
    ("ros_gz_sim", "gzserver"): GZ,
    ("ros_ign_gazebo", "create"): GZ,
}
SIM_COMMANDS = {
    ("gazebo",): CLASSIC,
    ("gzserver",): CLASSIC,
    ("gz", "sim"): GZ,
    ("ign", "gazebo"): GZ,
}
LAUNCH_SUFFIXES = (".launch.py", ".launch.xml", ".launch.yaml", ".launch.yml", "_launch.py")
LAUNCH_DIR_SUFFIXES = (".py", ".xml", ".yaml", ".yml")
MAX_INCLUDE_DEPTH = 8
MAX_DOCS = 400  # launch documents read in one check (a file under several argument sets)


@dataclass(frozen=True)
class Run:
    """One launch file as `ros2 launch` would start it, its includes merged in."""

    root: Path
    docs: tuple[LaunchDoc, ...]
    nodes: tuple[Node, ...]  # active or maybe active (None), own and included and implied
    processes: tuple[Process, ...]
    moveit: tuple[MoveItLaunch, ...]
    descriptions: tuple[Description, ...]
    global_params: Mapping[str, object]
    sims: Mapping[str, Where]  # CLASSIC / GZ -> where the launch starts it
    included: Mapping[str, Include] = field(default_factory=dict)  # file -> its include

    @property
    def package_root(self) -> Path:
        """The launch file's directory (for messages)."""
        return self.root.parent


def launch_files(pkg: Package) -> list[Path]:
    """The launch files of a ROS 2 package (none for a catkin package: roslaunch's)."""
    if pkg.ros1:
        return []
    out = []
    for f in pkg.files:
        name = f.name
        in_launch_dir = "launch" in f.relative_to(pkg.root).parts[:-1]
        if name.endswith(LAUNCH_SUFFIXES) or (in_launch_dir and name.endswith(LAUNCH_DIR_SUFFIXES)):
            out.append(f)
    return out


@dataclass
class Loader:
    """Reads launch documents (cached per file and arguments) and follows includes."""

    ws: Workspace
    implied: Callable[[MoveItLaunch], list[Node]]  # the nodes a MoveIt generator starts
    cache: dict[tuple[Path, tuple[tuple[str, str | None], ...]], LaunchDoc] = field(
        default_factory=dict
    )
    problems: dict[str, Problem] = field(default_factory=dict)

    def doc(self, path: Path, args: Mapping[str, str | None]) -> LaunchDoc | None:
        """A launch file read under `args`, cached; None past MAX_DOCS."""
        key = (path, tuple(sorted(args.items())))
        if key in self.cache:
            return self.cache[key]
        if len(self.cache) >= MAX_DOCS:
            return None
        shares = Shares(self.ws.dirs)
        try:
            if path.suffix == ".py":
                text = self.ws.jail.text(path, "launch file")
                if "generate_launch_description" not in text:
                    self.cache[key] = LaunchDoc(path)  # a helper module, not a launch file
                    return self.cache[key]
                doc = read_python_launch(path, text, shares, args)
            else:
                doc = read_xml_launch(self.ws.jail, path, shares, args)
        except InputError as exc:
            doc = LaunchDoc(path, problems=(Problem.of(exc, path),))
        for p in doc.problems:
            self.problems.setdefault(p.file, p)
        self.cache[key] = doc
        return doc

    def run(self, root: Path) -> Run | None:
        """The launch started from `root` with its defaults, includes merged."""
        top = self.doc(root, {})
        if top is None or top.problems:
            return None
        docs: list[LaunchDoc] = []
        sims: dict[str, Where] = {}
        included: dict[str, Include] = {}
        self._collect(top, docs, sims, included, 0)
        nodes = [n for d in docs for n in d.nodes if n.active is not False]
        moveit = tuple(m for d in docs for m in d.moveit)
        for m in moveit:
            nodes += self.implied(m)
        for n in nodes:
            fam = SIM_NODES.get((n.package or "", n.executable or ""))
            if fam is not None:
                sims.setdefault(fam, n.where)
        processes = tuple(p for d in docs for p in d.processes if p.active is not False)
        for p in processes:
            for prefix, fam in SIM_COMMANDS.items():
                if tuple(t.rsplit("/", 1)[-1] if t else "" for t in p.cmd[: len(prefix)]) == prefix:
                    sims.setdefault(fam, p.where)
        params: dict[str, object] = {}
        for d in docs:
            params.update(d.global_params)
        descriptions = {x.key: x for d in docs for x in d.descriptions}
        return Run(
            root,
            tuple(docs),
            tuple(nodes),
            processes,
            moveit,
            tuple(descriptions.values()),
            params,
            sims,
            included,
        )

    def _collect(
        self,
        doc: LaunchDoc,
        docs: list[LaunchDoc],
        sims: dict[str, Where],
        included: dict[str, Include],
        depth: int,
    ) -> None:
        if any(d.path == doc.path for d in docs) or depth > MAX_INCLUDE_DEPTH:
            return
        docs.append(doc)
        for inc in doc.includes:
            if inc.active is False or inc.target is None:
                continue
            uri = split_package_uri(inc.target)
            if uri is not None:
                fam = SIM_INCLUDES.get((uri[0], Path(uri[1]).name))
                if fam is not None:
                    sims.setdefault(fam, inc.where)
                continue
            path = self._file(Path(inc.target))
            if path is not None:
                sub = self.doc(path, inc.args)
                if sub is not None and not sub.problems:
                    included.setdefault(str(sub.path), inc)
                    self._collect(sub, docs, sims, included, depth + 1)

    def _file(self, path: Path) -> Path | None:
        """An included launch file under DIR.

        Found by name inside its package when the install layout differs from the source
        tree (an ament_python package's `share/` mapping).
        """
        if path.is_file() and self.ws.jail.allows(path):
            return path
        pkg = self.ws.owner(path)
        if pkg is None:
            return None
        same = [f for f in pkg.files if f.name == path.name]
        return same[0] if len(same) == 1 else None


def implied_nodes(m: MoveItLaunch, controllers: list[str], config: Path | None) -> list[Node]:
    """The nodes a moveit_configs_utils generator starts (its launches.py), for the rules."""
    where = m.where
    made: list[Node] = []

    def add(package: str, executable: str, **kw: object) -> None:
        made.append(replace(Node(where, package, executable), implied_by=m.generator, **kw))  # type: ignore[arg-type]

    demo = m.generator == "generate_demo_launch"
    if demo or m.generator == "generate_rsp_launch":
        add("robot_state_publisher", "robot_state_publisher")
    if demo or m.generator == "generate_move_group_launch":
        add("moveit_ros_move_group", "move_group")
    if demo or m.generator == "generate_moveit_rviz_launch":
        add("rviz2", "rviz2")
    if demo:
        add(
            "controller_manager",
            "ros2_control_node",
            param_files=(str(config),) if config is not None else (),
        )
    if demo or m.generator == "generate_spawn_controllers_launch":
        for c in [*controllers, "joint_state_broadcaster"]:
            add("controller_manager", "spawner", arguments=(c,))
    return made
