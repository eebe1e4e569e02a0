"""The robot a viewer shows: URDF text, named poses, tool point and the joints `--q` sets.

Shared by `view`, `render` and `tree`: a spec is built in memory (xacro
expansion, nothing written); a URDF is read strictly; a foreign xacro file is expanded
in safe mode, or by xacro itself with --trust-xacro (see armcli.urdf.source).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from armcli.errors import InputError
from armcli.io.names import did_you_mean
from armcli.robot.jointvalues import parse_joint_values
from armcli.robot.tool import ToolPoint, tool_point
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile, RobotInput, lookup_for, urdf_text
from armcli.urdf.tree import tree_from_urdf


@dataclass(frozen=True)
class RobotSource:
    """A robot to show: URDF text plus what a spec adds (named poses, tool point)."""

    xml: str
    source: str
    name: str
    mesh_dir: Path | None
    joints: tuple[str, ...]  # the joints `--q a,b,...` assigns, in order
    poses: dict[str, dict[str, float]] = field(default_factory=dict)
    tool: ToolPoint | None = None
    search: MeshSearch = field(default_factory=MeshSearch)  # --package-dir
    notes: tuple[str, ...] = ()  # what reading a xacro file reported (Urdf.notes)
    file: RobotFile | None = None  # what was read (the planning panel loads its model from it)


def load_robot(given: RobotInput | Path) -> RobotSource:
    """Spec YAML (built in memory), URDF or xacro file -> RobotSource.

    Mesh URIs resolve with armcli.urdf.meshes (honouring the --package-dir options in
    `given.packages`) and must stay inside the allowed roots; the tool point is
    armcli.robot.tool's. A bare path is read in safe mode with no xacro arguments.
    """
    if not isinstance(given, RobotInput):
        given = RobotInput((given,))
    path = given.file()
    robot = given.read(path)
    spec = robot.spec
    where = lookup_for(spec, given.packages)  # the spec's recorded packages too
    if spec is not None:
        return RobotSource(
            xml=urdf_text(robot.robot),
            source=str(path),
            name=spec.name,
            mesh_dir=None,
            joints=tuple(spec.movable_arm_joints()),
            poses={p: spec.pose(p) for p in spec.poses},
            tool=tool_point(robot.robot, spec),
            search=where,
            file=robot,
        )
    urdf = robot.robot
    tree = tree_from_urdf(urdf)
    return RobotSource(
        xml=urdf_text(urdf),
        source=str(path),
        name=tree.robot or path.stem,
        mesh_dir=path.parent,
        joints=tuple(j.name for j in tree.movable()),
        tool=tool_point(urdf),
        search=where,
        notes=urdf.notes,
        file=robot,
    )


def parse_q(text: str, robot: RobotSource) -> dict[str, float]:
    """`0.3,pi/4` (in robot.joints order) or `joint=0.3,other=pi/4` -> {joint: value}.

    The one rule for joint values (robot.jointvalues), as `plan --to` reads them.
    """
    return parse_joint_values(text, robot.joints, "q")


def pose_q(robot: RobotSource, pose: str | None, q: str | None) -> dict[str, float]:
    """The joint values a `--pose NAME` or `--q VALUES` option stands for."""
    if pose is not None and q is not None:
        raise InputError("give `pose` or `q`, not both", field="pose")
    if pose is not None:
        if pose not in robot.poses:
            known = ", ".join(robot.poses) or "(none: a URDF has no named poses)"
            raise InputError(
                f"unknown pose {pose!r}; {did_you_mean(pose, robot.poses)}known: {known}",
                field="pose",
            )
        return dict(robot.poses[pose])
    return parse_q(q, robot) if q is not None else {}
