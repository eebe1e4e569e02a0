"""`armcli render` as one library call: the robot at a pose drawn into a PNG, headless.

`render` reads the robot (view.scene), puts it at the pose asked for (a named pose, joint
values, or q = 0) snapped into its limits, draws it from two viewpoints (view.png) or,
with the reach asked for, with the tool point's envelope and the targets' verdicts
(view.reach), and writes the PNG. What it noticed on the way comes back as lines for the
caller to print: notes (a value snapped into its range), warnings (a mesh it could not
draw: a picture of the rest beats none) and the reach's lines.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from armcli.analysis.workspace import describe, verdict
from armcli.errors import InputError
from armcli.io.outdir import check_output_file
from armcli.urdf.source import RobotInput
from armcli.view.png import MESH_HINT, RenderResult, load_urdf, render_png, snapped
from armcli.view.scene import load_robot, pose_q


@dataclass(frozen=True)
class Picture:
    """A written render: the file, what it shows, and what to tell the user."""

    result: RenderResult  # the PNG's path, size and the tool point
    poses: Mapping[str, Mapping[str, float]]  # the robot's named poses
    notes: tuple[str, ...]  # what reading the robot said (`note: ...`, `warning: ...`)
    snapped: tuple[str, ...]  # joint values moved into their limits
    warnings: tuple[str, ...]  # meshes not drawn
    lines: tuple[str, ...]  # the reach envelope and each target's verdict


def render(
    robot: RobotInput,
    out: Path,
    *,
    pose: str | None = None,
    q: str | None = None,
    size: tuple[int, int] = (1200, 600),
    reach: bool = False,
    targets: Sequence[Sequence[float]] = (),
) -> Picture:
    """Draw `robot` at `pose` (or joint values `q`, else q = 0) into the PNG `out`."""
    check_output_file(out, "out", robot.files())  # before any work; never over the robot
    src = load_robot(robot)
    values = pose_q(src, pose, q)
    skipped: dict[str, str] = {}
    said: dict[str, str] = {}  # what trimesh said about a mesh it drew (a missing texture)
    urdf = load_urdf(src.xml, src.source, src.mesh_dir, src.search, skipped, said)
    values, snaps = snapped(urdf, values)
    field = "pose" if pose else "q"
    lines: list[str] = []
    if reach or targets:
        if src.tool is None:
            raise InputError("the robot has no links: no tool point to reach with", field="reach")
        from armcli.view.reach import render_reach_png  # Pinocchio: only for the reach

        pic = render_reach_png(
            urdf,
            src.xml,
            src.source,
            values,
            out,
            tool=src.tool,
            name=src.name,
            size=size,
            targets=list(targets),
            field=field,
        )
        res = pic.render
        lines = [describe(pic.workspace), *(verdict(p) for p in pic.points)]
    else:
        res = render_png(urdf, values, out, tool=src.tool, name=src.name, size=size, field=field)
    warnings = [
        f"{src.source}: mesh {uri!r} {why}, not drawn"
        + (f" ({MESH_HINT})" if why == "not found" else "")
        for uri, why in skipped.items()
    ]
    warnings += [
        f"{src.source}: mesh {uri!r}: {what}; drawn without it" for uri, what in said.items()
    ]
    return Picture(res, src.poses, tuple(src.notes), tuple(snaps), tuple(warnings), tuple(lines))
