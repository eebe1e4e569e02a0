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
from armcli.plan.matrixcache import cached_pairs, matrix_key
from armcli.ros.collision_matrix import DEFAULT_SEED, compute_collision_matrix
from armcli.urdf.doc import Urdf
from armcli.urdf.meshes import MeshSearch, confined_mesh_xml
from armcli.urdf.read import parse_root
from armcli.urdf.source import RobotFile

MAX_SRDF_BYTES = 8 * 1024 * 1024


@dataclass(frozen=True)
class Group:
    """A planning group as the SRDF writes it: joints, links, chains and other groups."""

    name: str
    joints: tuple[str, ...] = ()
    links: tuple[str, ...] = ()  # each stands for the joint above it
    chains: tuple[tuple[str, str], ...] = ()  # (base_link, tip_link)
    groups: tuple[str, ...] = ()  # subgroups by name
    line: int | None = None


@dataclass(frozen=True)
class Srdf:
    """An SRDF's disabled collision pairs, named joint states and planning groups."""

    disabled: tuple[tuple[str, str], ...] = ()
    group_states: dict[str, dict[str, float]] = field(default_factory=dict)
    groups: dict[str, Group] = field(default_factory=dict)
    source: str = "<srdf>"

    def group_joints(self, name: str, urdf: Urdf) -> tuple[str, ...]:
        """The joints of planning group `name` in `urdf`, in document order.

        As MoveIt resolves them: listed joints, the joint above each listed link, every
        joint of a chain from base to tip, and the subgroups'. InputError naming an
        unknown group or joint, or a chain whose tip is not below its base.
        """
        if name not in self.groups:
            valid = ", ".join(self.groups) or "none"
            raise InputError(f"unknown planning group {name!r}; valid: {valid}", field="group")
        above = {j.child: j for j in urdf.joints if j.child}
        known = {j.name for j in urdf.joints}
        found: set[str] = set()
        todo, seen = [name], set()
        while todo:
            g = self.groups.get(todo.pop())
            if g is None or g.name in seen:
                continue
            seen.add(g.name)
            todo.extend(g.groups)

            def refuse(message: str, g: Group = g) -> InputError:
                return InputError(message, file=self.source, line=g.line, field=f"group {g.name}")

            for j in g.joints:
                if j not in known:
                    raise refuse(f"joint {j!r} is not in {urdf.source}")
                found.add(j)
            found.update(above[lk].name for lk in g.links if lk in above)
            for base, tip in g.chains:
                link: str | None = tip  # walked up to the base
                chain: list[str] = []
                for _ in range(len(above) + 1):  # bounded: a malformed tree may loop
                    if link == base or link not in above:
                        break
                    chain.append(above[link].name)
                    link = above[link].parent
                if link != base:
                    raise refuse(f"chain tip {tip!r} is not below base {base!r}")
                found.update(chain)
        return tuple(j.name for j in urdf.joints if j.name in found)


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
    return Srdf(tuple(disabled), states, _groups(root, path), str(path))


def _groups(root: Any, path: Path) -> dict[str, Group]:
    """The top-level <group> elements by name."""
    out: dict[str, Group] = {}
    for el in root.findall("group"):
        name = el.get("name")
        if not name:
            raise InputError("needs a name", file=path, line=_line(el), field="<group>")
        chains = []
        for c in el.findall("chain"):
            base, tip = c.get("base_link"), c.get("tip_link")
            if not base or not tip:
                raise InputError("a chain needs base_link and tip_link", file=path,
                                 line=_line(c), field=f"group {name}")  # fmt: skip
            chains.append((base, tip))
        out[name] = Group(
            name,
            tuple(n for j in el.findall("joint") if (n := j.get("name"))),
            tuple(n for lk in el.findall("link") if (n := lk.get("name"))),
            tuple(chains),
            tuple(n for g in el.findall("group") if (n := g.get("name"))),
            _line(el),
        )
    return out


def allowed_pairs(
    robot: RobotFile, srdf: Srdf | None, search: MeshSearch | None = None
) -> tuple[tuple[str, str], ...]:
    """Link pairs never checked against each other: the SRDF's, else ros-package's matrix.

    `search`: the package lookup the collision meshes are resolved with (the same the
    planner's own geometry uses), so a `package://` mesh loads here too. The matrix is
    computed once per robot and kept in the user's cache (plan.matrixcache).
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

    def compute() -> tuple[tuple[str, str], ...]:
        matrix = compute_collision_matrix(
            text, samples=COLLISION_SAMPLES, seed=DEFAULT_SEED, source=urdf.source, poses=poses
        )
        return tuple((d.link1, d.link2) for d in matrix.disabled)

    key = matrix_key(text, poses, COLLISION_SAMPLES, DEFAULT_SEED)
    return cached_pairs(key, [lk.name for lk in urdf.links], compute)
