"""A placement as `armcli place` asks for it: one library call, its files and its summary.

`place_robot` loads the robot on its virtual base among the scene's objects
(`plan.mobile.virtual`), places it (`plan.mobile.place`) and returns what the command
prints and writes: the JSON document (its keys are the command's interface), the text
lines, the Nav2 goal and the plot as bytes, for the caller to write together.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from armcli.io.scene import require_file
from armcli.plan.mobile.nav2 import nav2_goal
from armcli.plan.mobile.place import TOLERANCE, Placement, place
from armcli.plan.mobile.virtual import MobileRobot, load_mobile
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile

KEYS = ("status", "base", "joints", "tool_error_m", "tip_margin_m", "region", "time_s", "reason")


@dataclass(frozen=True)
class Placed:
    """A finished placement and what it was asked."""

    mobile: MobileRobot
    placement: Placement
    target: tuple[float, float, float]
    start: tuple[float, float, float]
    tolerance: float

    def document(self) -> dict[str, Any]:
        """The JSON summary (KEYS, in order)."""
        v, r = self.placement.verdict, self.placement.region
        return {
            "status": "placed",
            "base": {"x": v.base[0], "y": v.base[1], "yaw": v.base[2]},
            "joints": dict(zip(self.placement.joints, v.q.tolist(), strict=True)),
            "tool_error_m": v.error,
            "tip_margin_m": v.margin,
            "region": {"x": list(r.x), "y": list(r.y), "yaw": list(r.yaw)},
            "time_s": self.placement.time_s,
            "reason": None,
        }

    def lines(self) -> list[str]:
        """The text summary, one fact per line."""
        p, v, r = self.placement, self.placement.verdict, self.placement.region
        x, y, yaw = v.base
        at = ", ".join(f"{c:g}" for c in self.target)
        sx, sy, syaw = self.start
        margin = "no support polygon" if v.margin is None else f"{v.margin * 1e3:.1f} mm"
        return [
            f"placed the base for the tool ({self.mobile.robot.tool_label}) to reach {at} m "
            f"({p.method}, {p.checks} collision checks, {p.time_s * 1e3:.1f} ms)",
            f"  base: x {x:.4f} m, y {y:.4f} m, yaw {math.degrees(yaw):.2f}° "
            f"({p.cost:.3f} m of wheel travel from {sx:g}, {sy:g}, {math.degrees(syaw):g}°)",
            "  arm: " + ", ".join(f"{n} {q:.4f}" for n, q in zip(p.joints, v.q, strict=True)),
            f"  tool error {v.error * 1e3:.2f} mm; tip-over margin {margin}",
            f"  region: x {r.x[0]:.4f}..{r.x[1]:.4f} m, y {r.y[0]:.4f}..{r.y[1]:.4f} m, "
            f"yaw {math.degrees(r.yaw[0]):.2f}..{math.degrees(r.yaw[1]):.2f}°",
            f"  Nav2 goal tolerances: xy {r.xy_tolerance * 1e3:.1f} mm, "
            f"yaw {math.degrees(r.yaw_tolerance):.2f}°",
        ]

    def files(self, output: Path | None, plot: Path | None) -> dict[Path, bytes]:
        """The Nav2 goal YAML and the plot PNG, as bytes by path."""
        files: dict[Path, bytes] = {}
        if output is not None:
            files[output] = nav2_goal(self.placement, self.target, self.start)
        if plot is not None:
            from armcli.plan.mobile.placeplot import place_png  # matplotlib: only for a plot

            files[plot] = place_png(
                self.mobile, self.placement, self.target, self.start, self.tolerance
            )
        return files


def failed_document(reason: str) -> dict[str, Any]:
    """The JSON summary of a placement that found no pose."""
    doc: dict[str, Any] = dict.fromkeys(KEYS)
    doc.update(status="failed", reason=reason)
    return doc


def place_robot(
    robot_file: RobotFile,
    target: Sequence[float],
    *,
    scene: Path | None = None,
    start: Sequence[float] = (0.0, 0.0, 0.0),
    tolerance: float = TOLERANCE,
    search: MeshSearch | None = None,
) -> Placed:
    """Place `robot_file`'s base for its tool to reach `target` (see `plan.mobile.place`)."""
    if scene is not None:
        require_file(scene)
    mobile = load_mobile(robot_file, scene=scene, search=search)
    placement = place(mobile, target, start, tolerance=tolerance)
    t = (float(target[0]), float(target[1]), float(target[2]))
    s = (float(start[0]), float(start[1]), float(start[2]))
    return Placed(mobile, placement, t, s, tolerance)
