"""The one JointTrajectory layout `plan` writes, read without the general YAML reader.

armcli writes its planned trajectories in a fixed layout (plan.output): comment lines, then
`header: {frame_id: "..."}`, `joint_names: ["a", "b"]`, `points:` and four lines per
point, every number Python's shortest repr of a float, times as integer `sec` and
`nanosec`. A document in exactly that layout, with names of letters, digits and `_./-`
only, is turned here line by line into the data the safe YAML reader builds from it: the
same floats (YAML reads each of these number forms as `float(text)`), ints, strings and
key order. Anything else (another layout, a name or number of another form) gives None
and is read by the YAML reader. Reading a 60 s plan back this way takes milliseconds where
the general reader takes a second; tests/trajectory/test_jointtext.py checks that both readers
give the same data.
"""

from __future__ import annotations

import re
from typing import Any

from armcli.io.yaml import YamlDoc

# [bytes] a file in plan's layout may be this large (a 60 s plan of 7 joints is ~2.6 MB);
# anything else still goes through the YAML reader's 1 MB cap
MAX_PLAN_BYTES = 64_000_000
_NAME = r'"[A-Za-z0-9_./-]*"'
_FLOAT = r"-?(?:[0-9]+\.[0-9]+(?:e[-+][0-9]+)?|[0-9]+e[-+][0-9]+)"
_INT = r"(?:0|[1-9][0-9]*)"
_HEADER = re.compile(rf"header: \{{frame_id: ({_NAME})\}}")
_NAMES = re.compile(rf"joint_names: \[({_NAME}(?:, {_NAME})*)\]")
_ROWS = (
    re.compile(rf"  - positions: \[({_FLOAT}(?:, {_FLOAT})*)\]"),
    re.compile(rf"    velocities: \[({_FLOAT}(?:, {_FLOAT})*)\]"),
    re.compile(rf"    accelerations: \[({_FLOAT}(?:, {_FLOAT})*)\]"),
)
_TIME = re.compile(rf"    time_from_start: \{{sec: ({_INT}), nanosec: ({_INT})\}}")
_KEYS = ("positions", "velocities", "accelerations")


def canonical_doc(text: str, source: str) -> YamlDoc | None:
    """The document's data when it is in plan's layout (no line numbers), else None."""
    lines = text.split("\n")
    k = 0
    while k < len(lines) and lines[k].startswith("#"):
        k += 1
    if len(lines) < k + 4 or lines[-1] != "" or lines[k + 2] != "points:":
        return None
    header, names = _HEADER.fullmatch(lines[k]), _NAMES.fullmatch(lines[k + 1])
    body = lines[k + 3 : -1]
    if header is None or names is None or not body or len(body) % 4:
        return None
    points = []
    for i in range(0, len(body), 4):
        point: dict[str, Any] = {}
        for key, pattern, line in zip(_KEYS, _ROWS, body[i : i + 3], strict=True):
            row = pattern.fullmatch(line)
            if row is None:
                return None
            point[key] = [float(v) for v in row.group(1).split(", ")]
        time = _TIME.fullmatch(body[i + 3])
        if time is None:
            return None
        point["time_from_start"] = {"sec": int(time.group(1)), "nanosec": int(time.group(2))}
        points.append(point)
    data = {
        "header": {"frame_id": header.group(1)[1:-1]},
        "joint_names": [n[1:-1] for n in names.group(1).split(", ")],
        "points": points,
    }
    return YamlDoc(data=data, source=source)
