"""CDR bytes of the sensor messages, their arrays written whole from numpy.

mcap_ros2's dynamic serialiser writes an array element by element in Python: a 160 x 120
point cloud (300 kB) took seconds per message. These writers lay out the same bytes
(ROS 2's XCDR1, little endian: the 4-byte encapsulation header, then each primitive
aligned to its size from the end of the header, strings and sequences as a uint32 count
first) for the few fixed message types the sensors publish; the tests read them back
with rosbags, an independent CDR decoder.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence

import numpy as np

HEADER = b"\x00\x01\x00\x00"  # CDR_LE encapsulation, no options


class Writer:
    """A CDR buffer: primitives aligned to their size, sequences counted."""

    def __init__(self) -> None:
        self.buf = bytearray(HEADER)

    def _align(self, size: int) -> None:
        pad = -(len(self.buf) - len(HEADER)) % size
        self.buf += b"\x00" * pad

    def put(self, fmt: str, *values: float | int) -> None:
        """Primitives of one struct format char (e.g. "I", "f", "d", "B"), aligned."""
        size = struct.calcsize("<" + fmt)
        self._align(size)
        self.buf += struct.pack(f"<{len(values)}{fmt}", *values)

    def string(self, text: str) -> None:
        """A string: length with its terminating NUL, bytes, NUL."""
        raw = text.encode("utf-8") + b"\x00"
        self.put("I", len(raw))
        self.buf += raw

    def array(self, values: np.ndarray, counted: bool = True) -> None:
        """A sequence (counted) or fixed array of one numeric dtype, little endian."""
        a = np.ascontiguousarray(values)
        if counted:
            self.put("I", a.size)
        self._align(a.dtype.itemsize)
        self.buf += a.astype(a.dtype.newbyteorder("<"), copy=False).tobytes()

    def header(self, ns: int, frame: str) -> None:
        """std_msgs/Header: builtin_interfaces/Time stamp, frame_id."""
        self.put("i", ns // 1_000_000_000)
        self.put("I", ns % 1_000_000_000)
        self.string(frame)

    def bytes(self) -> bytes:
        """The message."""
        return bytes(self.buf)


def laser_scan(ns: int, frame: str, angles: Sequence[float], ranges: np.ndarray) -> bytes:
    """sensor_msgs/LaserScan.

    `angles`: min, max, increment, time increment, scan time, range min, range max.
    """
    w = Writer()
    w.header(ns, frame)
    w.put("f", *angles)
    w.array(ranges.astype(np.float32))
    w.array(np.zeros(0, dtype=np.float32))  # intensities: none
    return w.bytes()


def image(ns: int, frame: str, encoding: str, pixels: np.ndarray) -> bytes:
    """sensor_msgs/Image of a (height, width[, channels]) array, rows packed."""
    w = Writer()
    w.header(ns, frame)
    height, width = pixels.shape[:2]
    w.put("I", height, width)
    w.string(encoding)
    w.put("B", 0)  # is_bigendian
    w.put("I", pixels[0].nbytes if height else 0)
    w.array(np.ascontiguousarray(pixels).view(np.uint8).reshape(-1))
    return w.bytes()


def camera_info(ns: int, frame: str, size: tuple[int, int], K: np.ndarray) -> bytes:
    """sensor_msgs/CameraInfo of an ideal pinhole: plumb_bob, no distortion, P = [K | 0]."""
    w = Writer()
    w.header(ns, frame)
    w.put("I", size[1], size[0])  # height, width
    w.string("plumb_bob")
    w.array(np.zeros(5))
    w.array(K.astype(np.float64).ravel(), counted=False)
    w.array(np.eye(3).ravel(), counted=False)
    w.array(np.hstack([K, np.zeros((3, 1))]).ravel(), counted=False)
    w.put("I", 0, 0)  # binning
    w.put("I", 0, 0, 0, 0)  # roi: x_offset, y_offset, height, width
    w.put("B", 0)  # roi.do_rectify
    return w.bytes()


FLOAT32 = 7  # sensor_msgs/PointField.FLOAT32


def point_cloud(ns: int, frame: str, points: np.ndarray, dense: bool) -> bytes:
    """sensor_msgs/PointCloud2 of float32 x, y, z: `points` (height, width, 3)."""
    w = Writer()
    w.header(ns, frame)
    height, width = points.shape[:2]
    w.put("I", height, width)
    w.put("I", 3)
    for i, name in enumerate("xyz"):
        w.string(name)
        w.put("I", 4 * i)
        w.put("B", FLOAT32)
        w.put("I", 1)
    w.put("B", 0)  # is_bigendian
    w.put("I", 12, 12 * width)  # point_step, row_step
    w.array(np.ascontiguousarray(points, dtype=np.float32).view(np.uint8).reshape(-1))
    w.put("B", int(dense))
    return w.bytes()


def imu(ns: int, frame: str, reading: np.ndarray, variance: tuple[float, float]) -> bytes:
    """sensor_msgs/Imu.

    `reading`: quaternion (x, y, z, w), angular velocity [rad/s], linear acceleration
    [m/s²]; `variance`: the gyro's and the accelerometer's per axis.
    """
    w = Writer()
    w.header(ns, frame)
    w.put("d", *reading[:4])
    w.array(np.zeros(9), counted=False)  # the orientation is the truth: no error to state
    w.put("d", *reading[4:7])
    w.array(np.eye(3).ravel() * variance[0], counted=False)
    w.put("d", *reading[7:10])
    w.array(np.eye(3).ravel() * variance[1], counted=False)
    return w.bytes()
