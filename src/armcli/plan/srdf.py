"""What planning needs from an SRDF, and the allowed-collision matrix when there is none.

Without `--srdf` the matrix is the one `ros-package` writes into the generated SRDF: the
same function (ros.collision_matrix), the same sample count, seed and named poses, so a
pair `plan` checks is a pair MoveIt checks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from armcli.defaults import COLLISION_SAMPLES
from armcli.errors import InputError
from armcli.io.userfile import read_regular
from armcli.ros.collision_matrix import DEFAULT_SEED, compute_collision_matrix
from armcli.urdf.meshes import MeshSearch, confined_mesh_xml
from armcli.urdf.read import parse_root
from armcli.urdf.source import RobotFile

MAX_SRDF_BYTES = 8 * 1024 * 1024


@dataclass(frozen=True)
class Srdf:
    """An SRDF's disabled collision pairs and named joint states (group_state)."""

    disabled: tuple[tuple[str, str], ...] = ()
    group_states: dict[str, dict[str, float]] = field(default_factory=dict)


def _line(el: Any) -> int | None:
    line = el.sourceline
    return line if isinstance(line, int) else None


def read_srdf(path: Path) -> Srdf:
    """Read `disable_collisions` and `group_state` entries; InputError with file and line."""
    data = read_regular(path, max_bytes=MAX_SRDF_BYTES, what="SRDF")
    root = parse_root(data, str(path))
    disabled = []
    for el in root.iter("disable_collisions"):
        a, b = el.get("link1"), el.get("link2")
        if not a or not b:
            raise InputError("needs link1 and link2", file=path, line=_line(el),
                             field="disable_collisions")  # fmt: skip
        disabled.append((a, b))
    states: dict[str, dict[str, float]] = {}
    for el in root.iter("group_state"):
        name = el.get("name")
        if not name:
            raise InputError("needs a name", file=path, line=_line(el), field="group_state")
        values = states.setdefault(name, {})
        for j in el.iter("joint"):
            jname, raw = j.get("name"), j.get("value")
            try:
                value = float(raw or "")
            except ValueError:
                value = math.nan
            if not jname or not math.isfinite(value):
                raise InputError(f"joint needs a name and a finite value, got {raw!r}",
                                 file=path, line=_line(j),
                                 field=f"group_state {name}")  # fmt: skip
            values[jname] = value
    return Srdf(tuple(disabled), states)


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
