"""`place --plot`: the floor seen from above, with where the base may stand.

Drawn: the scene's objects (outlines from above; those low enough to meet the base filled
dark, higher ones such as a table top hatched), the base positions that serve the target
(`Judge` on the coarse candidates of `plan.mobile.candidates`: every configuration, every
few degrees of yaw) shaded, the chosen pose with the robot's collision shapes at it and
its heading, the Nav2 tolerance circle, the start and the target. matplotlib is imported
inside, drawn on a bare Agg figure as `sim.plot` does.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from armcli.analysis.support import convex_hull
from armcli.plan.mobile.candidates import (
    PASSES,
    ordered,
    planar_family,
    sampled_family,
    standing,
)
from armcli.plan.mobile.judge import Judge
from armcli.plan.mobile.objects import outline, world_objects
from armcli.plan.mobile.place import Placement, turn_radius
from armcli.plan.mobile.virtual import MobileRobot
from armcli.robot.collision import box_corners, geometry_links, placements

MAX_SHADED = 6000  # candidate poses judged for the shading
SAMPLED_EVERY = 15  # of another arm's candidates, one in this many is judged for the shading


def robot_outlines(
    mobile: MobileRobot, base: Sequence[float], q: np.ndarray
) -> list[tuple[str, list[tuple[float, float]]]]:
    """Each collision shape's outline from above (its box's hull) at the pose: (link, points)."""
    robot = mobile.robot
    boxes = box_corners(robot.robot, robot.geometry, robot.q(mobile.x(base, q)))
    return [
        (link, convex_hull([(float(x), float(y)) for x, y in world[:, :2]]))
        for link, world in boxes
    ]


def serving(judge: Judge, start: Sequence[float], radius: float) -> np.ndarray:
    """Base positions (N, 2) that serve the target, among the coarse candidates.

    A planar arm's candidates at the target's height are judged as they are; another
    arm's (inverse kinematics at each pose) every SAMPLED_EVERY-th, to bound the time.
    """
    mobile = judge.mobile
    samples, step = PASSES[0]
    planar = mobile.planar is not None
    family = standing(judge, planar_family(judge, samples) if planar else sampled_family(judge, 0))
    out, seen = [], 0
    for chunk in ordered(family, judge.target, start, radius, step, judge.tolerance):
        for c in chunk:
            seen += 1
            if c.nearest:
                ok = judge.judge(c.base, c.q, c.miss).ok
            elif not planar and seen % SAMPLED_EVERY == 0:
                ok = judge.at(c.base, c.q).ok
            else:
                continue
            if ok:
                out.append(c.base[:2])
        if seen >= MAX_SHADED:
            break
    return np.array(out).reshape(-1, 2)


def _objects(ax: Any, mobile: MobileRobot, base_top: float) -> None:
    from matplotlib.patches import Polygon

    for obj in world_objects(mobile.scene):
        hull, bottom, _ = outline(obj)
        low = bottom < base_top
        ax.add_patch(
            Polygon(
                hull,
                closed=True,
                facecolor="0.35" if low else "none",
                edgecolor="0.2",
                hatch=None if low else "//",
                alpha=0.8,
            )
        )
        cx, cy = np.mean(np.array(hull), axis=0)
        ax.annotate(
            obj.id, (cx, cy), ha="center", va="center", fontsize=7, color="white" if low else "0.1"
        )


def place_png(
    mobile: MobileRobot,
    placement: Placement,
    target: Sequence[float],
    start: Sequence[float],
    tolerance: float,
) -> bytes:
    """The PNG bytes of the plot (see the module docstring)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Polygon

    v = placement.verdict
    judge = Judge(mobile, target, tolerance)
    fig = Figure(figsize=(7.0, 7.6))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    shapes = robot_outlines(mobile, v.base, v.q)
    base_links = set(mobile.base_links)
    _objects(ax, mobile, _base_top(mobile, v.base, v.q, base_links))
    ok = serving(judge, start, turn_radius(mobile))
    ax.scatter(
        ok[:, 0],
        ok[:, 1],
        s=4,
        color="C2",
        alpha=0.35,
        lw=0,
        label="base positions that reach the target",
    )
    for link, hull in shapes:
        is_base = link in base_links
        ax.add_patch(
            Polygon(
                hull,
                closed=True,
                facecolor="C0" if is_base else "C1",
                alpha=0.45 if is_base else 0.6,
                edgecolor="C0",
            )
        )
    x, y, yaw = v.base
    size = max(max(np.ptp(np.array(h), axis=0)) for _, h in shapes)  # the robot's extent
    ax.arrow(
        x, y, 0.4 * size * math.cos(yaw), 0.4 * size * math.sin(yaw), width=0.02 * size, color="C0"
    )
    ax.add_patch(
        Circle(
            (x, y),
            max(placement.region.xy_tolerance, 1e-4),
            fill=False,
            color="C3",
            lw=1.0,
            label="Nav2 xy_goal_tolerance",
        )
    )
    ax.plot([start[0]], [start[1]], "ko", ms=5, label="start")
    ax.plot([target[0]], [target[1]], "r*", ms=14, label=f"target (z = {target[2]:g} m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(
        f"armcli place: base at ({x:.3f}, {y:.3f}) m, yaw {math.degrees(yaw):.1f}°; "
        f"{placement.cost:.2f} m of wheel travel",
        fontsize=10,
    )
    # below the floor, not on it: a corner legend hid objects and serving poses
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2, fontsize=8)
    fig.subplots_adjust(bottom=0.2)
    ax.grid(True, alpha=0.3)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    return buf.getvalue()


def _base_top(mobile: MobileRobot, base: Sequence[float], q: np.ndarray, links: set[str]) -> float:
    """[m] the top of the base's collision shapes: objects lower than this meet the base."""
    robot = mobile.robot
    poses = placements(robot.robot, robot.geometry, robot.q(mobile.x(base, q)))
    owners = geometry_links(robot.model, robot.geometry)
    top = 0.0
    for T, g, link in zip(poses, robot.geometry.geometryObjects, owners, strict=True):
        if link not in links:
            continue
        g.geometry.computeLocalAABB()
        radius = (
            float(
                np.linalg.norm(
                    np.asarray(g.geometry.aabb_local.max_) - np.asarray(g.geometry.aabb_local.min_)
                )
            )
            / 2
        )
        top = max(top, float(T[2, 3]) + radius)
    return top
