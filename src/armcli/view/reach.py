"""Where the tool point can go, drawn over the robot: `armcli render --reach`.

The reachable region is the cloud of tool positions from seeded uniform draws of the
chain's joints within their limits (`analysis.workspace`, the sampler `check` uses, here
denser), coloured by height, over the robot at the rendered pose; joints off the chain
(a torso, the wheels) stay at that pose. Each `--reach-point` is a marker: a green ring
when inverse kinematics reaches it within REACH_TOL, a red cross joined by a dashed line
to the closest position the arm gets to when it does not.
"""

from __future__ import annotations

import io
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from armcli.analysis.workspace import (
    Chain,
    ReachPoint,
    Workspace,
    envelope,
    reach_point,
    sample,
)
from armcli.errors import InputError
from armcli.io.files import write_file_atomic
from armcli.robot.frames import link_frame
from armcli.robot.model import Robot
from armcli.robot.tool import ToolPoint
from armcli.urdf.read import parse_urdf
from armcli.view.png import DEFAULT_SIZE, DPI, RenderResult, full_configuration, render_figure

REACH_SAMPLES = 6000  # drawn points: a filled region at 1200x600 px, ~1 s to draw
CLOUD_SIZE = 2.0  # [pt²] marker area of a cloud point
CLOUD_ALPHA = 0.25
CAPTION_WIDTH = 150  # [characters]
CAPTION_SPACE = 0.16  # share of the height below the views, for the caption


@dataclass(frozen=True)
class ReachPicture:
    """What `render_reach_png` drew: the file, the envelope and the points' verdicts."""

    render: RenderResult
    workspace: Workspace
    points: tuple[ReachPoint, ...]


def reach_of(
    xml: str,
    source: str,
    tool: ToolPoint,
    q: Mapping[str, float],
    targets: Sequence[Sequence[float]] = (),
    samples: int = REACH_SAMPLES,
) -> tuple[Chain, NDArray[np.float64], Workspace, tuple[ReachPoint, ...]]:
    """The chain at pose `q`, its sampled tool positions (n, 3) [m], envelope and verdicts."""
    robot = Robot.load(parse_urdf(xml.encode("utf-8"), source), strict=False)
    if link_frame(robot.model, tool.link) is None:
        raise InputError(f"no link {tool.link!r} for the tool point", file=source)
    chain = Chain(robot, tool, q)
    if not chain.joints:
        raise InputError(
            f"no moving joint between the root and {tool.label}: nothing to reach with",
            file=source,
        )
    cloud = sample(chain, samples)
    points = tuple(reach_point(chain, cloud, t) for t in targets)
    return chain, cloud.p, envelope(chain, cloud), points


def render_reach_png(
    urdf: Any,
    xml: str,
    source: str,
    q: Mapping[str, float],
    out: str | Path,
    *,
    tool: ToolPoint,
    name: str = "robot",
    size: Sequence[int] = DEFAULT_SIZE,
    targets: Sequence[Sequence[float]] = (),
    field: str | None = None,
) -> ReachPicture:
    """Draw the robot at `q` with its tool point's reachable region; write a PNG atomically."""
    full = full_configuration(urdf, q, field=field)
    chain, cloud, ws, points = reach_of(xml, source, tool, full, targets)
    marks = np.array([p.target for p in points]).reshape(-1, 3)
    closest = np.array([chain.position([v for _, v in p.q]) for p in points]).reshape(-1, 3)

    def overlay(ax: Any) -> None:
        ax.scatter(
            cloud[:, 0],
            cloud[:, 1],
            cloud[:, 2],
            c=cloud[:, 2],
            cmap="viridis",
            s=CLOUD_SIZE,
            alpha=CLOUD_ALPHA,
            depthshade=False,
            linewidths=0,
        )
        for p, near in zip(points, closest, strict=True):
            if p.reachable:
                ax.scatter(
                    *p.target,
                    s=60,
                    facecolors="none",
                    edgecolors="green",
                    linewidths=1.5,
                    depthshade=False,
                )
            else:
                ax.scatter(*p.target, s=60, color="red", marker="x", depthshade=False)
                ax.plot(*zip(p.target, near, strict=True), "--", color="red", lw=1.0)

    extent = np.concatenate([cloud, marks])
    fig = render_figure(urdf, full, tool=tool, name=name, size=size, overlay=overlay, extent=extent)
    fig.subplots_adjust(bottom=CAPTION_SPACE)
    fig.text(0.5, 0.01, caption(ws, points), ha="center", va="bottom", fontsize=9)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    path = write_file_atomic(out, buf.getvalue())
    tip = chain.position([dict(full).get(j.name, 0.0) for j in chain.joints])
    result = RenderResult(
        Path(path), int(size[0]), int(size[1]), full, (float(tip[0]), float(tip[1]), float(tip[2]))
    )
    return ReachPicture(result, ws, points)


def caption(ws: Workspace, points: Sequence[ReachPoint]) -> str:
    """The picture's legend: the envelope's numbers and the points' markers."""
    text = (
        f"reach of {ws.point}: max {ws.max_reach:.3f} m from the shoulder "
        f"({', '.join(f'{v:.3f}' for v in ws.shoulder)}), height {ws.min_height:.3f}.."
        f"{ws.max_height:.3f} m, horizontal {ws.max_horizontal:.3f} m; {ws.samples} "
        "sampled tool positions, coloured by height"
    )
    if points:
        n = sum(p.reachable for p in points)
        text += f"; {n}/{len(points)} points reached (ring: reached, cross: out of reach)"
    return textwrap.fill(text, CAPTION_WIDTH)
