"""The planned motion as JointTrajectory YAML that `armcli simulate --trajectory` runs unchanged.

Every point has positions, velocities, accelerations and time_from_start ({sec, nanosec},
as ROS writes it). Floats are written with Python's shortest round-trip repr, so reading
the file back gives exactly the numbers certified (plan.api certifies the parsed file).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence

import numpy as np

from armcli.plan.timing import Timed
from armcli.trajectory.message import Trajectory, loads_trajectory


def _floats(values: Iterable[float]) -> str:
    return "[" + ", ".join(repr(float(v) + 0.0) for v in values) + "]"


def trajectory_yaml(
    joints: Sequence[str], timed: Timed, *, frame_id: str, comment: str = ""
) -> bytes:
    """The JointTrajectory document; `comment` lines go first (no timestamps: reproducible)."""
    lines = [f"# {c}" for c in comment.splitlines() if c]
    names = ", ".join(json.dumps(j) for j in joints)  # JSON strings are YAML scalars
    lines += [f"header: {{frame_id: {json.dumps(frame_id)}}}", f"joint_names: [{names}]", "points:"]
    ns = np.rint(timed.times * 1e9).astype(np.int64)
    for k in range(len(ns)):
        sec, nanosec = divmod(int(ns[k]), 1_000_000_000)
        lines += [
            f"  - positions: {_floats(timed.positions[k])}",
            f"    velocities: {_floats(timed.velocities[k])}",
            f"    accelerations: {_floats(timed.accelerations[k])}",
            f"    time_from_start: {{sec: {sec}, nanosec: {nanosec}}}",
        ]
    return ("\n".join(lines) + "\n").encode("utf-8")


def read_back(text: bytes, limits: dict[str, tuple[float, float]]) -> Timed:
    """The written document parsed as `simulate` parses it.

    No size cap: the document is armcli's own, just written (a 60 s plan is ~2.6 MB).
    """
    traj: Trajectory = loads_trajectory(
        text.decode("utf-8"), limits, source="<plan>", max_bytes=None
    )
    assert traj.velocities is not None and traj.accelerations is not None
    return Timed(traj.times, traj.positions, traj.velocities, traj.accelerations)
