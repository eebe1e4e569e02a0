"""`trajectory_msgs/JointTrajectory`-shaped input and its interpolation.

The YAML mirrors the ROS message (`header.frame_id`, `joint_names`, `points` with
`positions` and optional `velocities`, `accelerations`, `effort`, `time_from_start`), so
the payload of `ros2 topic pub /set_joint_trajectory ...` reads as ROS reads it, including
the brace form `{0.5, 0.3}` (see armcli.trajectory.brace).

Interpolation follows ros2_control's joint_trajectory_controller: per segment, linear
when the points give positions only, cubic when they give velocities, quintic when they
also give accelerations. When the first point's time is > 0 the trajectory starts from
the current state (velocity and acceleration as given, zero by default); a first point at
time 0 is taken as the reference from the start. After the last point the reference holds
its position with zero velocity. `effort` is accepted and ignored (the simulated
controller is position-commanded). A point without `time_from_start` is reached
DEFAULT_SEGMENT_S after the previous one (the first after the start), since ROS's default
of 0 would ask for an instantaneous jump.
"""

from __future__ import annotations

import contextlib
import difflib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from armcli.errors import Problem, SpecError, one_per_kind
from armcli.io.yaml import MAX_YAML_BYTES, FlowKeys, YamlDoc, dotted, loads_yaml, read_text
from armcli.trajectory.brace import BraceNotes
from armcli.trajectory.jointtext import MAX_PLAN_BYTES, canonical_arrays

DEFAULT_SEGMENT_S = 1.0  # [s] time given to a point without time_from_start
MIN_SEGMENT_S = 1e-6  # [s] shorter segments make the interpolated reference overflow
MAX_TIME_S = 1e6  # [s] ~11.6 days: far beyond any simulation worth running step by step
LIMIT_TOL = 1e-9  # [rad] slack when comparing positions with joint limits
_RULES = (LIMIT_TOL, MIN_SEGMENT_S, MAX_TIME_S)  # what trajectory.jointtext checks
CUTOFF = 0.6  # difflib similarity below which no "did you mean" is offered (spec.suggest's)
_TOP_KEYS = {"header", "joint_names", "points"}
_POINT_KEYS = {"positions", "velocities", "accelerations", "effort", "time_from_start"}
_HEADER_KEYS = {"frame_id", "stamp", "seq"}


@dataclass(frozen=True)
class Trajectory:
    """A validated trajectory: times strictly increasing, arrays (points, joints)."""

    joint_names: tuple[str, ...]
    times: np.ndarray  # (P,) time_from_start [s]
    positions: np.ndarray  # (P, m)
    velocities: np.ndarray | None  # (P, m) or None
    accelerations: np.ndarray | None  # (P, m) or None
    frame_id: str = ""
    source: str = "<string>"
    warnings: tuple[str, ...] = ()

    @property
    def duration(self) -> float:
        """Time of the last point [s]."""
        return float(self.times[-1])


def load_trajectory(
    path: str | Path,
    limits: Mapping[str, tuple[float, float]],
    *,
    clamp: bool = False,
    others: Mapping[str, str] = MappingProxyType({}),
) -> Trajectory:
    """Read and validate a trajectory file; `limits` maps each valid joint to (lower, upper)."""
    text = read_text(path, max_bytes=MAX_PLAN_BYTES, what="YAML file")  # YAML: 1 MB still
    return loads_trajectory(text, limits, source=str(path), clamp=clamp, others=others)


def loads_trajectory(
    text: str,
    limits: Mapping[str, tuple[float, float]],
    *,
    source: str = "<message>",
    clamp: bool = False,
    others: Mapping[str, str] = MappingProxyType({}),
    max_bytes: int | None = MAX_YAML_BYTES,
) -> Trajectory:
    """Validate a trajectory given as text, e.g. the `ros2 topic pub` payload.

    Plan's own layout is read by trajectory.jointtext (same data, fast; problems are reported from
    the YAML reader, which knows lines). `max_bytes`: None for armcli's own output.
    """
    fast = canonical_arrays(text)  # plan's layout, checked on arrays as parse_trajectory checks
    t = None if fast is None else fast.checked_times(limits, others, _RULES)
    if fast is not None and t is not None:
        return Trajectory(fast.names, t, *fast.rows(), frame_id=fast.frame_id, source=source)
    with contextlib.suppress(SpecError):  # reported below, from the YAML reader
        if fast is not None:  # e.g. out of limits: clamped, or refused with the YAML's lines
            return parse_trajectory(fast.doc(source), limits, clamp=clamp, others=others)
    doc = loads_yaml(text, source, flow_sets=True, max_bytes=max_bytes)
    return parse_trajectory(doc, limits, clamp=clamp, others=others)


class _Collector:
    def __init__(self, doc: YamlDoc) -> None:
        self.doc = doc
        self.problems: list[Problem] = []
        self.braces = BraceNotes()
        self.repeats: dict[tuple[str, ...], list[int]] = {}  # one message, counted, per typo

    def add(self, path: tuple[str | int, ...], msg: str) -> None:
        self.problems.append(Problem(dotted(path), msg, self.doc.line_of(path)))

    def once(self, path: tuple[str | int, ...], msg: str, key: tuple[str, ...] = ()) -> None:
        """Add the problem once per `key`, counting the repeats.

        The default key is the place without indices and the message (`points[*].postions`).
        """
        shape = key or (*(str(p) for p in path if not isinstance(p, int)), msg)
        if shape in self.repeats:
            self.repeats[shape][1] += 1
            return
        self.repeats[shape] = [len(self.problems), 0]
        self.add(path, msg)

    def finish(self) -> list[Problem]:
        """One problem per kind, saying how many more places repeat it (errors.one_per_kind)."""
        extra = [0] * len(self.problems)
        for index, more in self.repeats.values():
            extra[index] = more
        return one_per_kind(self.problems, extra)

    def unknown_keys(
        self, data: Mapping[str, Any], allowed: set[str], path: tuple[str | int, ...]
    ) -> set[str]:
        """Report keys outside `allowed` (did you mean ...?); the keys they suggest."""
        meant = set()
        for key in data:
            if key not in allowed:
                close = difflib.get_close_matches(str(key), sorted(allowed), n=1, cutoff=CUTOFF)
                hint = f"did you mean {close[0]!r}? " if close else ""
                meant.update(close)
                self.once((*path, key), f"unknown key; {hint}valid: {', '.join(sorted(allowed))}")
        return meant


def parse_trajectory(
    doc: YamlDoc,
    limits: Mapping[str, tuple[float, float]],
    *,
    clamp: bool = False,
    others: Mapping[str, str] = MappingProxyType({}),
) -> Trajectory:
    """Validate parsed YAML into a Trajectory, reporting every problem with its location.

    `others`: the robot's joints that are not arm joints, by name, with what they are
    ("a wheel joint"), so naming one says so rather than "unknown joint".
    """
    c = _Collector(doc)
    data = doc.data
    if not isinstance(data, dict):
        raise SpecError(doc.source, [Problem("", "a trajectory must be a YAML mapping", 1)])
    c.unknown_keys(data, _TOP_KEYS, ())
    frame_id = _frame_id(data.get("header"), c)
    names = _joint_names(data.get("joint_names"), limits, c, others)
    raw_points = data.get("points")
    if not isinstance(raw_points, list) or not raw_points:
        c.add(("points",), "needs a non-empty list of points")
        raw_points = []
    if c.problems:
        raise SpecError(doc.source, c.finish())
    m = len(names)
    fields: dict[str, list[list[float] | None]] = {
        "positions": [],
        "velocities": [],
        "accelerations": [],
    }
    times: list[float] = []
    for k, point in enumerate(raw_points):
        if not isinstance(point, dict):
            c.add(("points", k), "a point must be a mapping")
            continue
        meant = c.unknown_keys(point, _POINT_KEYS, ("points", k))
        for key in fields:  # a misspelt `positions` is reported once, not also as missing
            required = key == "positions" and key not in meant
            fields[key].append(_vector(point.get(key), m, ("points", k, key), c, required))
        if "effort" in point:
            _vector(point["effort"], m, ("points", k, "effort"), c, False)
        times.append(_time(point, times, k, c))
    _consistent(fields, c)
    if c.problems:
        raise SpecError(doc.source, c.finish())
    pos = np.array(fields["positions"], dtype=float)
    warnings = _check_limits(pos, names, limits, clamp, c)
    if c.problems:
        raise SpecError(doc.source, c.finish())
    vel, acc = fields["velocities"], fields["accelerations"]
    return Trajectory(
        joint_names=tuple(names),
        times=np.array(times, dtype=float),
        positions=pos,
        velocities=np.array(vel, dtype=float) if vel[0] is not None else None,
        accelerations=np.array(acc, dtype=float) if acc[0] is not None else None,
        frame_id=frame_id,
        source=doc.source,
        warnings=tuple(c.braces.warnings(doc.source) + warnings),
    )


def _frame_id(header: Any, c: _Collector) -> str:
    if header is None:
        return ""
    if not isinstance(header, dict):
        c.add(("header",), "must be a mapping like {frame_id: arm_base_link}")
        return ""
    c.unknown_keys(header, _HEADER_KEYS, ("header",))
    frame = header.get("frame_id", "")
    if not isinstance(frame, str):
        c.add(("header", "frame_id"), "must be a string")
        return ""
    return frame


def _joint_names(
    raw: Any, limits: Mapping[str, Any], c: _Collector, others: Mapping[str, str]
) -> list[str]:
    valid = ", ".join(limits)
    if not isinstance(raw, list) or not raw:
        c.add(("joint_names",), f"needs a non-empty list of joint names; valid: {valid}")
        return []
    seen: set[str] = set()
    for i, name in enumerate(raw):
        if isinstance(name, str) and name in others:
            c.add(
                ("joint_names", i), f"{name!r} is {others[name]}, not an arm joint; valid: {valid}"
            )
        elif not isinstance(name, str) or name not in limits:
            close = difflib.get_close_matches(str(name), list(limits), n=1, cutoff=CUTOFF)
            hint = f"did you mean {close[0]!r}? " if close else ""
            c.add(("joint_names", i), f"unknown joint {name!r}; {hint}valid: {valid}")
        elif name in seen:
            c.add(("joint_names", i), f"joint {name!r} listed twice")
        seen.add(str(name))
    return [str(n) for n in raw]


def _vector(
    raw: Any, m: int, path: tuple[str | int, ...], c: _Collector, required: bool
) -> list[float] | None:
    if isinstance(raw, FlowKeys):  # `{0.5, 0.3}`: what ROS 2 would send, or the reason not
        raw, refusal = c.braces.read(raw, m, dotted(path))
        if raw is None:
            c.add(path, refusal)
            return None
    if raw is None or raw == []:
        if required:
            c.add(path, f"missing: give {m} value(s), one per joint name")
        return None
    if not isinstance(raw, list):
        c.add(path, f"must be a list of {m} number(s)")
        return None
    if len(raw) != m:
        c.add(path, f"has {len(raw)} value(s) but joint_names has {m}")
        return None
    if all(type(x) is float and math.isfinite(x) for x in raw):  # as _finite finds, fast
        return list(raw)
    out: list[float] = []
    for i, x in enumerate(raw):
        if (value := _finite(x)) is None:
            c.add((*path, i), f"must be a finite number, got {_short(x)}")
            return None
        out.append(value)
    return out


def _finite(x: Any) -> float | None:
    """`x` as a finite float, or None (bools, strings, NaN/inf, ints beyond float range)."""
    if isinstance(x, bool) or not isinstance(x, int | float):
        return None
    with contextlib.suppress(OverflowError):  # an int beyond the float range
        value = float(x)
        return value if math.isfinite(value) else None
    return None


def _short(x: Any) -> str:
    text = repr(x)
    return text if len(text) <= 40 else text[:37] + "..."


def _time(
    point: dict[str, Any], previous: Sequence[float], k: int, c: _Collector, key: str = "points"
) -> float:
    """`time_from_start` of entry `k` of the list `key` [s] (seconds or {sec, nanosec}).

    Missing: DEFAULT_SEGMENT_S after the previous entry. drive.cmdvel reads its times so too.
    """
    path: tuple[str | int, ...] = (key, k, "time_from_start")
    last = previous[-1] if previous else 0.0
    raw = point.get("time_from_start")
    if raw is None:
        return last + DEFAULT_SEGMENT_S
    if isinstance(raw, dict):
        c.unknown_keys(raw, {"sec", "nanosec"}, path)
        sec, nsec = raw.get("sec", 0), raw.get("nanosec", 0)
        if not all(isinstance(x, int) and not isinstance(x, bool) for x in (sec, nsec)):
            c.add(path, "sec and nanosec must be integers")
            return last
        if not 0 <= nsec < 1_000_000_000:
            c.add((*path, "nanosec"), "must be in [0, 1e9)")
            return last
        seconds = _finite(sec)
        if seconds is None:
            c.add((*path, "sec"), f"must be a finite number of seconds, got {_short(sec)}")
            return last
        t = seconds + nsec * 1e-9
    elif _finite(raw) is not None:
        t = float(raw)
    else:
        c.add(path, f"must be seconds or {{sec, nanosec}}, got {_short(raw)}")
        return last
    if t < 0:
        c.add(path, f"must be >= 0, got {t:g}")
    elif t > MAX_TIME_S:
        c.add(path, f"must be <= {MAX_TIME_S:g} s, got {t:g}")
    elif previous and t <= last:
        c.add(path, f"times must increase: {t:g} s is not after {key[:-1]} {k - 1} at {last:g} s")
    elif 0 < t - last < MIN_SEGMENT_S:
        c.add(
            path,
            f"{t - last:g} s after the previous point: segments must last at least "
            f"{MIN_SEGMENT_S:g} s",
        )
    return float(t)


def _consistent(fields: dict[str, list[list[float] | None]], c: _Collector) -> None:
    """Velocities/accelerations are given on every point or on none (as JTC expects)."""
    for key in ("velocities", "accelerations"):
        given = [v is not None for v in fields[key]]
        if any(given) and not all(given):
            k = given.index(False)
            c.add(
                ("points", k, key),
                f"missing: {key} are given on other points, so every point needs them",
            )
    if all(a is not None for a in fields["accelerations"]) and not all(
        v is not None for v in fields["velocities"]
    ):
        c.add(
            ("points", 0, "velocities"), "accelerations need velocities too (quintic interpolation)"
        )


def _check_limits(
    pos: np.ndarray,
    names: Sequence[str],
    limits: Mapping[str, tuple[float, float]],
    clamp: bool,
    c: _Collector,
) -> list[str]:
    warnings = []
    degrees = _looks_like_degrees(pos, names, limits)
    for k in range(pos.shape[0]):
        for i, name in enumerate(names):
            lo, hi = limits[name]
            x = pos[k, i]
            if lo - LIMIT_TOL <= x <= hi + LIMIT_TOL:
                continue
            where = dotted(("points", k, "positions", i))
            msg = f"{x:g} is outside the limits of {name} [{lo:g}, {hi:g}]"
            if degrees:
                c.once(
                    ("points", k, "positions", i),
                    f"{msg}: looks like degrees: {x:g}° = {math.radians(x):.3f} rad; "
                    "positions are radians",
                    key=("degrees",),
                )
            elif clamp:
                pos[k, i] = min(max(x, lo), hi)
                warnings.append(f"{c.doc.source} {where}: {msg}; clamped to {pos[k, i]:g}")
            else:
                c.once(
                    ("points", k, "positions", i), f"{msg} (use --clamp to clamp)", ("limit", name)
                )
    return warnings


def _looks_like_degrees(
    pos: np.ndarray, names: Sequence[str], limits: Mapping[str, tuple[float, float]]
) -> bool:
    """Some position beyond a full turn, and every position within its limits in radians."""
    if not np.any(np.abs(pos) > 2 * math.pi):
        return False
    rad = np.radians(pos)
    lo = np.array([limits[n][0] for n in names]) - LIMIT_TOL
    hi = np.array([limits[n][1] for n in names]) + LIMIT_TOL
    return bool(np.all((rad >= lo) & (rad <= hi)))
