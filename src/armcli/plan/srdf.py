"""What planning needs from an SRDF, and the allowed-collision matrix when there is none.

Without `--srdf` the matrix is the one `ros-package` writes into the generated SRDF: the
same function (ros.collision_matrix), the same sample count, seed and named poses, so a
pair `plan` checks is a pair MoveIt checks.
"""

from __future__ import annotations

from armcli.defaults import COLLISION_SAMPLES
from armcli.ros.collision_matrix import DEFAULT_SEED, compute_collision_matrix
from armcli.urdf.meshes import MeshSearch, confined_mesh_xml
from armcli.urdf.source import RobotFile
from armcli.urdf.srdf import Group, Srdf, read_srdf

__all__ = ["Group", "Srdf", "allowed_pairs", "read_srdf"]  # the reader lives in urdf/srdf.py


def allowed_pairs(
    robot: RobotFile, srdf: Srdf | None, search: MeshSearch | None = None
) -> tuple[tuple[str, str], ...]:
    """Link pairs never checked against each other: the SRDF's, else ros-package's matrix.

    `search`: the package lookup the collision meshes are resolved with (the same the
    planner's own geometry uses), so a `package://` mesh loads here too.
    """
    if srdf is not None:
        return srdf.disabled
    poses = {n: robot.spec.pose(n) for n in robot.spec.poses} if robot.spec is not None else None
    urdf = robot.robot
    text = (
        urdf.text
        if search is None
        else confined_mesh_xml(urdf.text, urdf.source, search, collision_only=True)
    )
    matrix = compute_collision_matrix(
        text,
        samples=COLLISION_SAMPLES,
        seed=DEFAULT_SEED,
        source=robot.robot.source,
        poses=poses,
    )
    return tuple((d.link1, d.link2) for d in matrix.disabled)
