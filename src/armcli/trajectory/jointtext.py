"""The one JointTrajectory layout `plan` writes, read without the general YAML reader.

armcli writes its planned trajectories in a fixed layout (plan.output): comment lines, then
`header: {frame_id: "..."}`, `joint_names: ["a", "b"]`, `points:` and four lines per
point, every number Python's shortest repr of a float, times as integer `sec` and
`nanosec`. A document in exactly that layout, with names of letters, digits and `_./-`
only, is matched by one pattern and turned into arrays (`Canonical`) holding what the
safe YAML reader builds from it: the same floats (YAML reads each of these number forms
as `float(text)`), ints, strings and key order (`Canonical.doc`). Anything else (another
layout, a name or number of another form) gives None and is read by the YAML reader.
trajectory.message checks the arrays as it checks the YAML reader's points, without a Python
step per point: reading a 60 s plan back takes milliseconds where the general reader takes
a second; tests/trajectory/test_jointtext.py checks that both readers give the same data.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from armcli.io.yaml import YamlDoc

# [bytes] a file in plan's layout may be this large (a 60 s plan of 7 joints is ~2.6 MB);
# anything else still goes through the YAML reader's 1 MB cap
MAX_PLAN_BYTES = 64_000_000
_NAME = r'"[A-Za-z0-9_./-]*"'
_FLOAT = r"-?(?:[0-9]+\.[0-9]+(?:e[-+][0-9]+)?|[0-9]+e[-+][0-9]+)"
_INT = r"(?:0|[1-9][0-9]*)"
_HEADER = re.compile(rf"header: \{{frame_id: ({_NAME})\}}")
_NAMES = re.compile(rf"joint_names: \[({_NAME}(?:, {_NAME})*)\]")
_STAMPS = re.compile(rf"    time_from_start: \{{sec: ({_INT}), nanosec: ({_INT})\}}")


@dataclass(frozen=True)
class Canonical:
    """A document in plan's layout as arrays: the YAML reader's numbers, bit for bit."""

    frame_id: str
    names: tuple[str, ...]
    sec: np.ndarray  # (P,) int64 (an int beyond it: not this reader's)
    nanosec: np.ndarray  # (P,) int64
    values: np.ndarray  # (P, 3, n): positions, velocities, accelerations of each point

    def rows(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions, velocities, accelerations (P, n), each its own contiguous array."""
        p, v, a = (np.ascontiguousarray(self.values[:, i]) for i in range(3))
        return p, v, a

    def doc(self, source: str) -> YamlDoc:
        """The data the YAML reader builds from the document (no line numbers)."""
        points = [
            {"positions": p, "velocities": v, "accelerations": a,
             "time_from_start": {"sec": sec, "nanosec": nanosec}}
            for (p, v, a), sec, nanosec in zip(self.values.tolist(), self.sec.tolist(),
                                               self.nanosec.tolist(), strict=True)
        ]  # fmt: skip
        data = {"header": {"frame_id": self.frame_id}, "joint_names": list(self.names),
                "points": points}  # fmt: skip
        return YamlDoc(data=data, source=source)

    def checked_times(
        self, limits: Mapping[str, tuple[float, float]], others: Mapping[str, str],
        rules: tuple[float, float, float],
    ) -> np.ndarray | None:  # fmt: skip
        """The times [s] when every check trajectory.message makes passes, else None.

        `rules`: (position slack [rad], shortest segment [s], latest time [s]) as
        trajectory.message defines them. None: the YAML reader reads it again and says what fails.
        """
        tol, shortest, latest = rules
        names = self.names
        if len(set(names)) < len(names) or any(n not in limits or n in others for n in names):
            return None
        if not np.all(np.isfinite(self.values)) or np.any(self.nanosec >= 1_000_000_000):
            return None
        t = self.sec.astype(float) + self.nanosec.astype(float) * 1e-9  # as _time adds them
        gap = np.diff(t, prepend=0.0)
        if t[-1] > latest or np.any(gap[1:] <= 0) or np.any((gap > 0) & (gap < shortest)):
            return None
        lo, hi = (np.array([limits[n][i] for n in names]) for i in (0, 1))
        pos = self.values[:, 0]
        if np.any(pos < lo - tol) or np.any(pos > hi + tol):
            return None
        return t


def _head(text: str) -> tuple[str, str, str] | None:
    """(header line, joint_names line, the points' lines) after the comment lines."""
    at = 0
    while text.startswith("#", at):
        at = text.find("\n", at) + 1
        if at == 0:
            return None
    parts = text[at:].split("\n", 3)
    if len(parts) < 4 or parts[2] != "points:" or not parts[3].endswith("\n"):
        return None
    return parts[0], parts[1], parts[3]


def canonical_arrays(text: str) -> Canonical | None:
    """The document as arrays when it is in plan's layout, else None.

    One pattern checks every point's four lines at once; the numbers are converted as the
    YAML reader converts them (float(text)), without a Python step per point.
    """
    head = _head(text)
    if head is None:
        return None
    header, names = _HEADER.fullmatch(head[0]), _NAMES.fullmatch(head[1])
    if header is None or names is None:
        return None
    joints = tuple(n[1:-1] for n in names.group(1).split(", "))
    row = rf"\[{_FLOAT}(?:, {_FLOAT}){{{len(joints) - 1}}}\]"
    point = (rf"  - positions: {row}\n    velocities: {row}\n    accelerations: {row}\n"
             rf"    time_from_start: \{{sec: {_INT}, nanosec: {_INT}\}}\n")  # fmt: skip
    body = head[2]
    if re.fullmatch(rf"(?:{point})+", body) is None:
        return None
    stamps = _STAMPS.findall(body)
    if any(len(s) > 18 for pair in stamps for s in pair):  # beyond int64: the YAML reader's
        return None
    lines = body.split("\n")
    rows = ", ".join(
        line[line.index("[") + 1 : -1] for k, line in enumerate(lines[:-1]) if k % 4 != 3
    )
    # numpy's text conversion is Python's (PyOS_string_to_double): float(text), bit for bit
    values = np.fromstring(rows, dtype=float, sep=",").reshape(len(stamps), 3, len(joints))
    ints = np.array(stamps, dtype=np.int64).reshape(-1, 2)
    return Canonical(header.group(1)[1:-1], joints, ints[:, 0], ints[:, 1], values)


def canonical_doc(text: str, source: str) -> YamlDoc | None:
    """The document's data when it is in plan's layout (no line numbers), else None."""
    fast = canonical_arrays(text)
    return None if fast is None else fast.doc(source)
