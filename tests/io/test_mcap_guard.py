"""Crafted MCAPs for `view --replay` end in one input error (issue 27).

Before: a 50 kB zstd chunk declaring gigabytes ran to 1.7 GB and `internal error:
MemoryError`; an lz4 chunk bomb gave `internal error: RuntimeError`; a wrong schema, a
truncated message, a sequence length that lies, a chunk declaring 2^62 bytes and an
unknown compression all ended in `internal error`.
"""

from __future__ import annotations

import io
import struct
from pathlib import Path

import pytest

from armcli.errors import InputError
from armcli.io.mcap_guard import MAX_CHUNK_BYTES
from armcli.sim import rosbag
from tests.sim.test_rosbag_bounds import JOINT, _mcap

BOMB_BYTES = 2 * MAX_CHUNK_BYTES  # what the bombs inflate to: past the bound, cheap to build


def _record(opcode: int, body: bytes) -> bytes:
    return bytes([opcode]) + struct.pack("<Q", len(body)) + body


def _string(s: str) -> bytes:
    return struct.pack("<I", len(s.encode())) + s.encode()


def _chunk(compression: str, data: bytes, size: int) -> bytes:
    body = struct.pack("<QQQI", 0, 0, size, 0) + _string(compression)
    return _record(0x06, body + struct.pack("<Q", len(data)) + data)


def _file(*records: bytes) -> bytes:
    """magic, header, the records, data end, an empty footer, magic."""
    magic = b"\x89MCAP0\r\n"
    header = _record(0x01, _string("ros2") + _string("test"))
    footer = _record(0x02, struct.pack("<QQI", 0, 0, 0))
    return magic + header + b"".join(records) + _record(0x0F, struct.pack("<I", 0)) + footer + magic


def _zstd_zeros(n: int) -> bytes:
    import zstandard

    out = io.BytesIO()
    with zstandard.ZstdCompressor().stream_writer(out, closefd=False) as w:
        block = b"\0" * (1 << 20)
        for _ in range(n >> 20):
            w.write(block)
    return out.getvalue()


def _lz4_zeros(n: int) -> bytes:
    import lz4.frame

    c = lz4.frame.LZ4FrameCompressor()
    block = b"\0" * (1 << 20)
    return c.begin() + b"".join(c.compress(block) for _ in range(n >> 20)) + c.flush()


def _replay(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "crafted.mcap"
    path.write_bytes(data)
    rosbag.load_replay(path, [JOINT])


CRAFTED = {
    "zstd bomb declaring its size": (
        lambda: _chunk("zstd", _zstd_zeros(BOMB_BYTES), BOMB_BYTES),
        "declares",
    ),
    "zstd bomb declaring little": (
        lambda: _chunk("zstd", _zstd_zeros(BOMB_BYTES), 1000),
        "inflates to more than",
    ),
    "lz4 bomb": (lambda: _chunk("lz4", _lz4_zeros(BOMB_BYTES), 1000), "inflates to more than"),
    "chunk declaring 2^62 bytes": (lambda: _chunk("zstd", b"\x28\xb5\x2f\xfd", 2**62), "declares"),
    "unknown compression": (lambda: _chunk("brotli", b"x", 1), "unknown compression"),
    "damaged lz4": (lambda: _chunk("lz4", b"\x04\x22\x4d\x18garbage", 10), "damaged lz4"),
    "record longer than the file": (lambda: b"\x05" + struct.pack("<Q", 2**40), "longer than"),
}


@pytest.mark.parametrize("case", sorted(CRAFTED))
def test_crafted_chunks_are_one_input_error(case: str, tmp_path: Path) -> None:
    make, message = CRAFTED[case]
    with pytest.raises(InputError, match=message):
        _replay(tmp_path, _file(make()))


def test_a_valid_file_passes_the_guard(tmp_path: Path) -> None:
    run = rosbag.load_replay(_mcap(tmp_path / "ok.mcap", [0.0, 0.5, 1.0]), [JOINT])
    assert run.duration == pytest.approx(0.2)  # three states 0.1 s apart


@pytest.mark.parametrize("cut", [0.3, 0.6, 0.9])
def test_truncated_files_are_one_input_error(cut: float, tmp_path: Path) -> None:
    data = _mcap(tmp_path / "ok.mcap", [0.0, 0.5, 1.0]).read_bytes()
    with pytest.raises(InputError):
        _replay(tmp_path, data[: int(len(data) * cut)])


def _plain_mcap(path: Path) -> bytes:
    """A two-state /joint_states MCAP with uncompressed chunks (its bytes can be edited)."""
    from mcap.writer import CompressionType
    from mcap_ros2.writer import Writer

    with path.open("wb") as fh:
        writer = Writer(fh, compression=CompressionType.NONE)
        schema = writer.register_msgdef(
            rosbag.JOINT_STATE, rosbag.message_definition(rosbag.JOINT_STATE)
        )
        for k, q in enumerate([0.0, 0.5]):
            msg = {
                "header": {"stamp": {"sec": k, "nanosec": 0}, "frame_id": ""},
                "name": [JOINT],
                "position": [q],
                "velocity": [],
                "effort": [],
            }
            writer.write_message(rosbag.JOINT_STATES, schema, msg, log_time=k, publish_time=k)
        writer.finish()
    return path.read_bytes()


def test_wrong_schema_and_lying_sequences_are_one_input_error(tmp_path: Path) -> None:
    """Bytes around a message's name sequence set to 0, 0x7f, 0xff in turn (lengths that
    lie, truncated CDR, a schema that no longer parses): never anything but an InputError."""
    data = _plain_mcap(tmp_path / "ok.mcap")
    name = JOINT.encode()
    at = data.rfind(name)  # in the last message
    schema = data.find(b"sensor_msgs/msg/")
    assert at > 0 and schema > 0
    refused = 0
    for offset in [*range(-16, len(name) + 40), *range(schema - at, schema - at + 40)]:
        for value in (0x00, 0x7F, 0xFF):
            mutated = bytearray(data)
            mutated[at + offset] = value
            try:
                _replay(tmp_path, bytes(mutated))
            except InputError:
                refused += 1
    assert refused > 0  # and no other exception escaped


def _tf_mcap(path: Path, transforms: int, messages: int = 1) -> Path:
    """/joint_states plus /tf messages of `transforms` transforms each (chunked, zstd)."""
    from mcap_ros2.writer import Writer

    tf = {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": "a"},
        "child_frame_id": "b",
        "transform": {"translation": {"x": 0, "y": 0, "z": 0},
                      "rotation": {"x": 0, "y": 0, "z": 0, "w": 1}},
    }  # fmt: skip
    with path.open("wb") as fh:
        writer = Writer(fh)
        states = writer.register_msgdef(
            rosbag.JOINT_STATE, rosbag.message_definition(rosbag.JOINT_STATE)
        )
        tfs = writer.register_msgdef(
            rosbag.TF_MESSAGE, rosbag.message_definition(rosbag.TF_MESSAGE)
        )
        for k in range(messages):
            stamp = {"sec": k, "nanosec": 0}
            state = {"header": {"stamp": stamp, "frame_id": ""}, "name": [JOINT],
                     "position": [0.0], "velocity": [], "effort": []}  # fmt: skip
            writer.write_message(rosbag.JOINT_STATES, states, state, log_time=k, publish_time=k)
            writer.write_message(rosbag.TF, tfs, {"transforms": [tf] * transforms},
                                 log_time=k, publish_time=k)  # fmt: skip
        writer.finish()
    return path


def test_too_many_messages_are_refused_before_any_is_parsed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 42: 9 chunks of 450k tiny messages (a 9 MB file) took over 60 s and 2.5 GB.

    The bound is lowered for the test (a million messages take a minute to write); the count
    comes from the chunks' records, before the mcap reader parses or decodes anything.
    """
    from armcli.io import mcap_guard

    path = _mcap(tmp_path / "many.mcap", [0.1 * k for k in range(101)])
    monkeypatch.setattr(mcap_guard, "MAX_MESSAGES", 100)
    monkeypatch.setattr("mcap.reader.make_reader", None)  # never reached
    with pytest.raises(InputError, match="more than 100 messages, armcli's bound on a replay"):
        rosbag.load_replay(path, [JOINT])


def test_one_huge_tf_message_is_refused_before_it_is_decoded(tmp_path: Path) -> None:
    """Issue 42: one /tf message of 750k transforms loaded to 1 GB; here ~1.3 MB of them."""
    path = _tf_mcap(tmp_path / "tf.mcap", transforms=15_000)
    with pytest.raises(InputError, match=r"a message at byte \d+ is \d+ bytes, more than"):
        rosbag.load_replay(path, [JOINT])


def test_transforms_are_bounded_per_replay(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = _tf_mcap(tmp_path / "tf.mcap", transforms=40, messages=3)
    monkeypatch.setattr(rosbag, "MAX_REPLAY_TRANSFORMS", 100)
    with pytest.raises(InputError, match="more than 100 /tf transforms"):
        rosbag.load_replay(path, [JOINT])
    monkeypatch.setattr(rosbag, "MAX_REPLAY_TRANSFORMS", 120)
    assert rosbag.load_replay(path, [JOINT]).duration == pytest.approx(2.0)
