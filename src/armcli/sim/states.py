"""The joint-states file of `armcli simulate --output`: its schema, writer and reader.

The file mimics Gazebo's joint_state_publisher: one row per publish period (the spec's
`joint_state_publisher.update_rate`, 10 Hz) with columns `time` [s] and, per joint,
`NAME.position` [rad or m], `NAME.velocity` [rad/s or m/s], `NAME.effort` [N·m or N] and
`NAME.reference` (the position the controller was tracking). The reader (used by
`view --replay`) treats the file as user input: every cell is checked and errors name
the file, line and column.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from armcli.errors import InputError
from armcli.io.csvtable import CsvBounds, read_numeric_csv
from armcli.io.files import write_file_atomic
from armcli.sim.simulate import MAX_STEPS, SimResult

TIME = "time"
FIELDS = ("position", "velocity", "effort", "reference")  # per-joint columns, in file order
FLOAT_FMT = "{:.9g}"


def column(joint: str, field: str) -> str:
    """The column name of one joint's field: `NAME.field`."""
    return f"{joint}.{field}"


# -- writer ----------------------------------------------------------------------------------


def sample_steps(steps: int, dt: float, rate: float) -> np.ndarray:
    """The steps whose states the file holds: one per period 1/`rate` [Hz] from t = 0.

    `simulate` keeps only these (plus what a plot needs), so memory follows the output
    rate, not the number of steps.
    """
    period = 1.0 / rate
    n_samples = int(np.floor(steps * dt / period + 1e-9)) + 1
    idx = np.minimum(np.round(np.arange(n_samples) * period / dt).astype(np.int64), steps)
    return distinct(idx)


def distinct(steps: np.ndarray) -> np.ndarray:
    """Sorted step numbers without repeats (np.unique would import numpy.ma: 20 ms)."""
    s = np.sort(np.asarray(steps, dtype=np.int64))
    return s[np.concatenate(([True], s[1:] != s[:-1]))] if s.size else s


def sample_states(res: SimResult, rate: float) -> dict[str, np.ndarray]:
    """Columns `time`, `NAME.position|velocity|effort|reference` at `rate` [Hz].

    Raises:
        ValueError: `res` did not keep the states at those steps.
    """
    want = sample_steps(res.steps, res.dt, rate)
    rows = np.minimum(np.searchsorted(res.step, want), len(res.step) - 1)
    if not np.array_equal(res.step[rows], want):
        raise ValueError(f"the run did not keep the states at {rate:g} Hz")
    cols: dict[str, np.ndarray] = {TIME: res.t[rows]}
    for i, name in enumerate(res.joint_names):
        cols[column(name, "position")] = res.q[rows, i]
        cols[column(name, "velocity")] = res.v[rows, i]
        cols[column(name, "effort")] = res.tau[rows, i]
        cols[column(name, "reference")] = res.q_ref[rows, i]
    return cols


def states_bytes(cols: dict[str, np.ndarray], fmt: str) -> bytes:
    """CSV or JSON text of the sampled states (deterministic formatting)."""
    names = list(cols)
    if fmt == "json":
        data = {k: [float(FLOAT_FMT.format(x)) for x in v] for k, v in cols.items()}
        return (json.dumps(data, indent=1) + "\n").encode()
    lines = [",".join(names)]
    rows = np.column_stack([cols[k] for k in names])
    lines += [",".join(FLOAT_FMT.format(x) for x in row) for row in rows]
    return ("\n".join(lines) + "\n").encode()


def output_format(path: Path) -> str:
    """The joint-state file format named by the extension of `path`: "csv" or "json".

    Raises:
        InputError: any other extension.
    """
    ext = path.suffix.lower()
    if ext not in (".csv", ".json"):
        raise InputError(
            f"unknown output format {ext or '(none)'!r}; use .csv, .json or .mcap",
            field="output",
        )
    return ext[1:]


def write_states(path: Path, res: SimResult, rate: float) -> None:
    """Write the joint states sampled at `rate` [Hz] atomically, as CSV or JSON by extension."""
    write_file_atomic(path, states_bytes(sample_states(res, rate), output_format(path)))


# -- reader ----------------------------------------------------------------------------------


MAX_REPLAY_BYTES = 200_000_000
MAX_REPLAY_ROWS = MAX_STEPS  # the most states `simulate` records
MAX_REPLAY_COLUMNS = 1024  # time + 4 columns for each of 128 joints, with room to spare
MAX_REPLAY_CELLS = 25_000_000  # 200 MB as float64 (a 198 MB file of 2 rows took 2 GB)
REPLAY_BOUNDS = CsvBounds(MAX_REPLAY_BYTES, MAX_REPLAY_COLUMNS, MAX_REPLAY_ROWS, MAX_REPLAY_CELLS)


@dataclass(frozen=True)
class Replay:
    """A recorded run: time [s], joint positions and (where given) references over time."""

    source: str
    time: np.ndarray
    position: dict[str, np.ndarray]
    reference: dict[str, np.ndarray] = field(default_factory=dict)
    base: np.ndarray | None = None  # (N, 7) root in the world: x, y, z [m], w, x, y, z (a drive)

    @property
    def duration(self) -> float:
        """Length of the record [s]."""
        return float(self.time[-1] - self.time[0])

    def positions_at(self, t: float) -> dict[str, float]:
        """Linearly interpolated joint positions at time t [s] (clamped to the record)."""
        return {j: float(np.interp(t, self.time, v)) for j, v in self.position.items()}

    def base_at(self, t: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The root's position [m] and unit quaternion (w, x, y, z) at t, or None (no drive)."""
        if self.base is None:
            return None
        row = np.array([np.interp(t, self.time, self.base[:, i]) for i in range(7)])
        quat = row[3:] / max(float(np.linalg.norm(row[3:])), 1e-12)
        return row[:3], quat

    def reference_at(self, t: float) -> dict[str, float] | None:
        """The reference pose at t [s], or None where the file gives no reference then."""
        if not self.reference:
            return None
        i = int(np.clip(np.searchsorted(self.time, t, side="right") - 1, 0, len(self.time) - 1))
        ref = {j: float(v[i]) for j, v in self.reference.items()}
        return ref if all(math.isfinite(v) for v in ref.values()) else None


def load_replay(path: str | Path, joints: Sequence[str]) -> Replay:
    """Read a `simulate` CSV (time, NAME.position/.velocity/.effort/.reference) for `joints`."""
    source = str(path)
    table = read_numeric_csv(
        path, REPLAY_BOUNDS, lambda h: h.endswith((".reference", ".velocity", ".effort"))
    )  # bounded before allocating; duplicate columns refused
    header = table.header
    if not header or header[0] != TIME:
        raise InputError("first column must be 'time'", file=source, line=1)
    pos_cols = {h[: -len(".position")]: i for i, h in enumerate(header) if h.endswith(".position")}
    ref_cols = {
        h[: -len(".reference")]: i for i, h in enumerate(header) if h.endswith(".reference")
    }
    for name in [*pos_cols, *ref_cols]:
        if name not in joints:
            known = ", ".join(joints) or "(none)"
            raise InputError(f"unknown joint {name!r}; known: {known}", file=source, line=1)
    if not pos_cols:
        raise InputError("no NAME.position columns", file=source, line=1)
    if not len(table.values):
        raise InputError("no data rows", file=source, line=2)
    t = table.values[:, 0]
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if len(bad):
        line = int(table.lines[bad[0] + 1])
        raise InputError("time must increase", file=source, line=line, field="time")
    return Replay(
        source=source,
        time=t,
        position={j: table.values[:, i] for j, i in pos_cols.items()},
        reference={j: table.values[:, i] for j, i in ref_cols.items()},
        base=_base_pose(header, table.values),
    )


BASE_COLUMNS = tuple(f"base.{c}" for c in ("x", "y", "z", "roll", "pitch", "yaw"))


def _base_pose(header: Sequence[str], values: np.ndarray) -> np.ndarray | None:
    """(N, 7) x, y, z, w, x, y, z of a drive's `base.*` columns, else None."""
    if not all(c in header for c in BASE_COLUMNS):
        return None
    x, y, z, roll, pitch, yaw = (values[:, list(header).index(c)] for c in BASE_COLUMNS)
    cr, sr = np.cos(roll / 2), np.sin(roll / 2)
    cp, sp = np.cos(pitch / 2), np.sin(pitch / 2)
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    w = cr * cp * cy + sr * sp * sy  # R = Rz(yaw) Ry(pitch) Rx(roll), as URDF's rpy
    qx = sr * cp * cy - cr * sp * sy
    qy = cr * sp * cy + sr * cp * sy
    qz = cr * cp * sy - sr * sp * cy
    return np.column_stack([x, y, z, w, qx, qy, qz])
