"""The end-effector point every command reports, so check, simulate, view and render agree.

With a spec, it is the spec's `arm.tool` (a point fixed in a link, such as the hand's
tip). Otherwise it is the origin of the deepest link (of the spec's arm, or of a foreign
URDF): the link with the most movable joints between it and the root, the first in file
order on ties. Fixed joints do not count, so a sensor frame fixed to the last moving link
does not outrank the link itself unless it comes first in the file. MoveIt's planning
chain (`ros.srdf`) ends at the same link.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from armcli.urdf.doc import Urdf

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec


@dataclass(frozen=True)
class ToolPoint:
    """The end-effector point: `xyz` [m] fixed in `link`'s frame."""

    link: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def label(self) -> str:
        """How reports name the point: the link, plus the offset [m] when there is one."""
        if not any(self.xyz):
            return self.link
        return f"{self.link} + ({', '.join(f'{x:g}' for x in self.xyz)})"


def deepest_link(links: Sequence[str], joints: Iterable[tuple[str, str, bool]]) -> str:
    """The link with the most movable joints above it; the first in `links` on ties.

    `joints` are (parent, child, movable); a malformed tree (a cycle) stays bounded.
    """
    parent = {child: (par, moves) for par, child, moves in joints}

    def depth(link: str) -> int:
        n, cur = 0, link
        for _ in range(len(parent) + 1):
            if cur not in parent:
                break
            cur, moves = parent[cur]
            n += moves
        return n

    return max(links, key=depth)


def spec_tool(spec: RobotSpec) -> ToolPoint:
    """The spec's `arm.tool`, or else the deepest link of its arm (the rule above)."""
    t = spec.arm.tool
    if t is not None:
        return ToolPoint(t.link, (float(t.xyz[0]), float(t.xyz[1]), float(t.xyz[2])))
    joints = ((j.parent, j.child, j.type != "fixed") for j in spec.arm.joints.values())
    return ToolPoint(deepest_link(list(spec.arm.links), joints))


def tool_point(urdf: Urdf, spec: RobotSpec | None = None) -> ToolPoint | None:
    """The tool point of this URDF (see the module docstring); None for a URDF without links."""
    names = [lk.name for lk in urdf.links]
    if spec is not None and (tool := spec_tool(spec)).link in names:
        return tool
    if not names:
        return None
    joints = ((str(j.parent), str(j.child), j.type != "fixed") for j in urdf.joints)
    return ToolPoint(deepest_link(names, joints))
