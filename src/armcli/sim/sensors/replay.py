"""The scans, point clouds and world of a run's MCAP, read back for `view --replay`.

Any rosbag2 MCAP: every sensor_msgs/LaserScan topic becomes its returns (x, y, z in its
frame: range times the ray's direction, the no-returns left out), every PointCloud2 its
finite float32 x, y, z, each message at its header's time and frame; `/world`'s
visualization_msgs/MarkerArray (boxes, spheres, cylinders, triangle lists in `world`)
the objects to draw. The file is user input: its chunks are bounded before the reader
sees them (io.mcap_guard) and the points it may hold are bounded in all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from armcli.errors import InputError
from armcli.io.mcap_guard import check_chunks
from armcli.io.userfile import open_regular
from armcli.sim.rosbag import MAX_REPLAY_BYTES

LASER_SCAN, POINT_CLOUD = "sensor_msgs/msg/LaserScan", "sensor_msgs/msg/PointCloud2"
MARKER_ARRAY, WORLD_TOPIC = "visualization_msgs/msg/MarkerArray", "/world"
MAX_POINTS = 50_000_000  # points a replay keeps in all (~600 MB of float32)
FLOAT32 = 7  # sensor_msgs/PointField.FLOAT32


@dataclass(frozen=True)
class Track:
    """One topic's clouds: their times [s], frame and points (m_i, 3) in that frame."""

    topic: str
    frame: str
    time: np.ndarray
    points: tuple[np.ndarray, ...]
    kind: str = "scan"  # "scan" (LaserScan) or "cloud" (PointCloud2)

    def at(self, t: float) -> int | None:
        """The index of the last cloud at or before t, or None before the first."""
        i = int(np.searchsorted(self.time, t + 1e-9, side="right")) - 1
        return i if i >= 0 else None


@dataclass(frozen=True)
class WorldShape:
    """An object of `/world`: Marker type name, pose (x, y, z, qw, qx, qy, qz), scale, rgba."""

    kind: str  # box, sphere, cylinder, triangles
    pose: tuple[float, ...]
    scale: tuple[float, float, float]
    rgba: tuple[float, float, float, float]
    triangles: np.ndarray | None = None  # (n, 3, 3) for a triangle list


@dataclass(frozen=True)
class SensorReplay:
    """What a replay draws besides the robot."""

    tracks: tuple[Track, ...] = ()
    world: tuple[WorldShape, ...] = ()


def load_sensor_replay(path: str | Path) -> SensorReplay:
    """The scans, clouds and world objects of an MCAP (none: an empty SensorReplay)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    source = str(path)
    clouds: dict[str, list[tuple[float, str, np.ndarray]]] = {}
    kinds: dict[str, str] = {}
    world: tuple[WorldShape, ...] = ()
    total = 0
    try:
        with open_regular(path, max_bytes=MAX_REPLAY_BYTES, what="MCAP file") as fh:
            check_chunks(fh, source)
            reader = make_reader(fh, decoder_factories=[DecoderFactory()])
            for schema, channel, _raw, msg in reader.iter_decoded_messages():
                if schema is None:
                    continue
                if schema.name == MARKER_ARRAY and channel.topic == WORLD_TOPIC:
                    world = tuple(s for s in map(_shape, msg.markers) if s is not None)
                elif schema.name in (LASER_SCAN, POINT_CLOUD):
                    pts = _scan_points(msg) if schema.name == LASER_SCAN else _cloud_points(msg)
                    total += len(pts)
                    if total > MAX_POINTS:
                        raise InputError(f"more than {MAX_POINTS:,} points", file=source)
                    t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
                    clouds.setdefault(channel.topic, []).append((t, msg.header.frame_id, pts))
                    kinds[channel.topic] = "scan" if schema.name == LASER_SCAN else "cloud"
    except InputError:
        raise
    except Exception as exc:  # the mcap reader and the CDR decoder raise many kinds
        why = f"{type(exc).__name__}: {exc}"[:200]
        raise InputError(f"unreadable MCAP file: {why}", file=source) from None
    tracks = tuple(_track(topic, rows, kinds[topic]) for topic, rows in sorted(clouds.items()))
    return SensorReplay(tracks, world)


def _track(topic: str, rows: list[tuple[float, str, np.ndarray]], kind: str) -> Track:
    rows.sort(key=lambda r: r[0])
    time = np.array([r[0] for r in rows])
    return Track(topic, rows[0][1], time, tuple(r[2] for r in rows), kind)


def _scan_points(msg: Any) -> np.ndarray:
    r = np.asarray(msg.ranges, dtype=np.float64)
    a = msg.angle_min + np.arange(len(r)) * msg.angle_increment
    ok = np.isfinite(r)
    return np.column_stack([r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok]), np.zeros(ok.sum())])


def _cloud_points(msg: Any) -> np.ndarray:
    """The finite x, y, z of a PointCloud2 whose x, y, z are float32 fields."""
    fields = {f.name: f for f in msg.fields}
    if any(k not in fields or fields[k].datatype != FLOAT32 for k in "xyz") or msg.is_bigendian:
        return np.zeros((0, 3))
    n, step = msg.width * msg.height, msg.point_step
    data = bytes(msg.data)
    if n == 0 or step < 12 or len(data) < n * step:
        return np.zeros((0, 3))
    raw = np.frombuffer(data, dtype=np.uint8, count=n * step).reshape(n, step)
    xyz = np.column_stack(
        [raw[:, fields[k].offset : fields[k].offset + 4].copy().view("<f4")[:, 0] for k in "xyz"]
    )
    return np.asarray(xyz[np.all(np.isfinite(xyz), axis=1)], dtype=np.float64)


_KINDS = {1: "box", 2: "sphere", 3: "cylinder", 11: "triangles"}


def _shape(m: Any) -> WorldShape | None:
    kind = _KINDS.get(int(m.type))
    if kind is None or m.header.frame_id not in ("world", ""):
        return None  # objects on a link move with it: not drawn (Foxglove and RViz do)
    p, q, s, c = m.pose.position, m.pose.orientation, m.scale, m.color
    pose = (p.x, p.y, p.z, q.w, q.x, q.y, q.z)
    if not all(math.isfinite(v) for v in (*pose, s.x, s.y, s.z)):
        return None
    tris = None
    if kind == "triangles":
        pts = np.array([[v.x, v.y, v.z] for v in m.points], dtype=float)
        tris = pts[: len(pts) // 3 * 3].reshape(-1, 3, 3)
    return WorldShape(kind, pose, (s.x, s.y, s.z), (c.r, c.g, c.b, c.a or 1.0), tris)
