"""`--cmd-vel FILE.yaml`: the velocity commands a drive run sends on /cmd_vel.

The file is a mapping `commands:` whose entries are geometry_msgs/Twist fields
(`linear`, `angular`, each a mapping of `x`, `y`, `z` [m/s, rad/s], missing ones 0)
plus `time_from_start` (seconds or `{sec, nanosec}`, as in a JointTrajectory; a
missing one is 1 s after the previous command). Each command holds until the next,
as a message on /cmd_vel does; before the first one the robot is commanded to stand
still. gazebo_ros_diff_drive reads only `linear.x` and `angular.z`: other non-zero
components are accepted (the message has them) and named in a warning.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from armcli.errors import Problem, SpecError
from armcli.io.yaml import YamlDoc, dotted, load_yaml, loads_yaml
from armcli.trajectory.message import _Collector, _finite, _short, _time

_TOP_KEYS = {"commands"}
_COMMAND_KEYS = {"linear", "angular", "time_from_start"}
_AXES = ("x", "y", "z")
USED = (("linear", "x"), ("angular", "z"))  # what a differential drive can follow


@dataclass(frozen=True)
class CmdVel:
    """Validated commands: times strictly increasing [s], Twist parts per command."""

    times: np.ndarray  # (N,) [s]
    linear: np.ndarray  # (N, 3) [m/s]
    angular: np.ndarray  # (N, 3) [rad/s]
    source: str = "<string>"
    warnings: tuple[str, ...] = ()

    @property
    def duration(self) -> float:
        """Time of the last command [s]."""
        return float(self.times[-1])

    def at(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(linear.x [m/s], angular.z [rad/s]) in force at times `t`: zero before the first."""
        i = np.searchsorted(self.times, np.asarray(t, dtype=float), side="right") - 1
        ok = i >= 0
        j = np.maximum(i, 0)
        return np.where(ok, self.linear[j, 0], 0.0), np.where(ok, self.angular[j, 2], 0.0)


def load_cmd_vel(path: str | Path) -> CmdVel:
    """Read and validate a cmd_vel file; SpecError names the file, line and field."""
    return parse_cmd_vel(load_yaml(path))


def loads_cmd_vel(text: str, source: str = "<cmd_vel>") -> CmdVel:
    """Validate cmd_vel commands given as YAML text."""
    return parse_cmd_vel(loads_yaml(text, source))


def parse_cmd_vel(doc: YamlDoc) -> CmdVel:
    """Validate parsed YAML into CmdVel, reporting every problem with its location."""
    c = _Collector(doc)
    data = doc.data
    if not isinstance(data, dict):
        raise SpecError(
            doc.source,
            [
                Problem(
                    "",
                    "a cmd_vel file must be a YAML mapping with a "
                    "`commands:` list, e.g. commands: [{linear: {x: "
                    "0.2}, time_from_start: 1.0}]",
                    1,
                )
            ],
        )
    c.unknown_keys(data, _TOP_KEYS, ())
    raw = data.get("commands")
    if not isinstance(raw, list) or not raw:
        c.add(("commands",), "needs a non-empty list of {linear, angular, time_from_start}")
        raw = []
    times: list[float] = []
    parts: dict[str, list[list[float]]] = {"linear": [], "angular": []}
    for k, cmd in enumerate(raw):
        if not isinstance(cmd, dict):
            c.add(("commands", k), "a command must be a mapping")
            continue
        c.unknown_keys(cmd, _COMMAND_KEYS, ("commands", k))
        for part in parts:
            parts[part].append(_vector3(cmd.get(part), ("commands", k, part), c))
        times.append(_time(cmd, times, k, c, key="commands"))
    if c.problems:
        raise SpecError(doc.source, c.finish())  # one line per kind of problem
    linear, angular = np.array(parts["linear"]), np.array(parts["angular"])
    return CmdVel(
        times=np.array(times, dtype=float),
        linear=linear,
        angular=angular,
        source=doc.source,
        warnings=_ignored(linear, angular, doc.source),
    )


def _vector3(raw: Any, path: tuple[str | int, ...], c: _Collector) -> list[float]:
    if raw is None:
        return [0.0, 0.0, 0.0]
    if not isinstance(raw, Mapping):
        c.add(path, "must be a mapping like {x: 0.2, y: 0.0, z: 0.0}")
        return [0.0, 0.0, 0.0]
    c.unknown_keys(raw, set(_AXES), path)
    out = []
    for axis in _AXES:
        x = raw.get(axis, 0.0)
        value = _finite(x)
        if value is None:
            c.add((*path, axis), f"must be a finite number, got {_short(x)}")
            value = 0.0
        out.append(value)
    return out


def _ignored(linear: np.ndarray, angular: np.ndarray, source: str) -> tuple[str, ...]:
    """Warnings for the non-zero components a differential drive cannot follow."""
    out = []
    for part, values in (("linear", linear), ("angular", angular)):
        for i, axis in enumerate(_AXES):
            if (part, axis) in USED:
                continue
            rows = np.nonzero(values[:, i])[0]
            if rows.size:
                out.append(
                    f"{source} {dotted(('commands', int(rows[0]), part, axis))}: a "
                    f"differential drive follows linear.x and angular.z only; {part}.{axis} "
                    "is ignored"
                )
    return tuple(out)
