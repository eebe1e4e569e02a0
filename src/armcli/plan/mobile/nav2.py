"""A placement as a Nav2 goal: the pose to send and the tolerances its goal checker needs.

Nav2's NavigateToPose takes a geometry_msgs/PoseStamped; its controller stops once the
robot is within `xy_goal_tolerance` [m] and `yaw_goal_tolerance` [rad] of it (the goal
checker's parameters). The document holds the PoseStamped under `pose` (the frame is the
scene's world frame: Nav2's `map`; the pose is the region's goal, inside the region where
the placed pose is on its edge: plan.mobile.region) and the two tolerances beside it.
Floats are written with Python's shortest round-trip repr: the same placement gives the
same bytes.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence

from armcli.plan.mobile.place import Placement

FRAME = "map"  # the scene's world frame, as Nav2 names it


def _f(x: float) -> str:
    return repr(float(x) + 0.0)


def nav2_goal(placement: Placement, target: Sequence[float], start: Sequence[float]) -> bytes:
    """The Nav2 goal YAML of a placement (see the module docstring)."""
    x, y, yaw = placement.region.goal
    reach = ",".join(f"{v:g}" for v in target)
    origin = ",".join(f"{v:g}" for v in start)
    lines = [
        f"# armcli place --target {reach} --start {origin}: send `pose` to Nav2's",
        "# NavigateToPose; set its goal checker's tolerances to the two values below.",
        "pose:  # geometry_msgs/PoseStamped",
        f"  header: {{frame_id: {json.dumps(FRAME)}}}",
        "  pose:",
        f"    position: {{x: {_f(x)}, y: {_f(y)}, z: 0.0}}",
        f"    orientation: {{x: 0.0, y: 0.0, z: {_f(math.sin(yaw / 2))}, "
        f"w: {_f(math.cos(yaw / 2))}}}",
        f"xy_goal_tolerance: {_f(placement.region.xy_tolerance)}  # [m]",
        f"yaw_goal_tolerance: {_f(placement.region.yaw_tolerance)}  # [rad]",
    ]
    return ("\n".join(lines) + "\n").encode("utf-8")
