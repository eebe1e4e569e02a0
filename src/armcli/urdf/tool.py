"""The end-effector point every command reports, so check, simulate, view and render agree.

With a spec, it is the spec's `arm.tool` (a point fixed in a link, such as the hand's
tip). Without one (a foreign URDF), it is the origin of the deepest link: the link with
the most movable joints between it and the root, the first in file order on ties. Fixed
joints do not count, so a sensor frame fixed to the last moving link does not outrank the
link itself unless it comes first in the file.
"""

from __future__ import annotations

from dataclasses import dataclass

from armcli.spec.model import RobotSpec
from armcli.urdf.doc import Urdf


@dataclass(frozen=True)
class ToolPoint:
    """The end-effector point: `xyz` [m] fixed in `link`'s frame."""

    link: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)


def tool_point(urdf: Urdf, spec: RobotSpec | None = None) -> ToolPoint | None:
    """The tool point of this URDF (see the module docstring); None for a URDF without links."""
    names = [lk.name for lk in urdf.links]
    if spec is not None and spec.arm.tool is not None and spec.arm.tool.link in names:
        t = spec.arm.tool
        return ToolPoint(t.link, (float(t.xyz[0]), float(t.xyz[1]), float(t.xyz[2])))
    if not names:
        return None
    parent = {j.child: j for j in urdf.joints}

    def depth(link: str) -> int:
        n, cur = 0, link
        for _ in range(len(parent) + 1):  # bounded: a malformed file may hold a cycle
            j = parent.get(cur)
            if j is None:
                break
            n += j.type != "fixed"
            cur = str(j.parent)
        return n

    return ToolPoint(max(names, key=depth))
