"""An MCAP file walked and its chunks inflated under a bound before the mcap library reads it.

The mcap reader trusts a chunk's declared size (zstd output buffers are allocated from
it) and inflates lz4 chunks without any bound: a 50 kB zstd chunk reached 1.7 GB and
`internal error: MemoryError`, an lz4 bomb `internal error: RuntimeError` (issue 27).
`check_chunks` reads every top-level record header, refuses a record longer than the
file, a compression other than none, zstd and lz4, a chunk declaring more than
MAX_CHUNK_BYTES, and a chunk whose data inflates (streaming, bounded) to anything but
its declared size; so the reader that follows never allocates more than the bound.

It also counts the messages, in chunks and outside them (issue 42: 9 chunks of 450k tiny
`/joint_states` messages, a 9 MB file, took `view --replay` over 60 s and 2.5 GB, and one
`/tf` message of 750k transforms 1 GB): a file of more than MAX_MESSAGES messages, or one
message longer than MAX_MESSAGE_BYTES, is refused before any message is parsed.
"""

from __future__ import annotations

import io
import struct
from typing import BinaryIO

from armcli.errors import InputError

MAX_CHUNK_BYTES = 64 * 1024 * 1024  # rosbag2 and the mcap writer make chunks of about 1-4 MiB
MAX_RECORDS = 10_000_000
# The mcap reader parses ~10-30 µs per message, decoding ~30-70 µs more: 1,000,000 messages
# is simulate's three topics for 1.8 h at 50 Hz, read in under a minute
MAX_MESSAGES = 1_000_000
MAX_MESSAGE_BYTES = 1 << 20  # a JointState of 128 joints is ~8 kB, a /tf of 300 links ~30 kB
MAGIC = b"\x89MCAP0\r\n"
CHUNK, FOOTER, MESSAGE = 0x06, 0x02, 0x05
COMPRESSIONS = ("", "zstd", "lz4")
_CHUNK_HEAD = struct.Struct("<QQQII")  # start, end, uncompressed size, crc, compression length


def _bad(message: str, file: str) -> InputError:
    return InputError(f"unreadable MCAP file: {message}", file=file)


def _inflate(compression: str, data: bytes, limit: int) -> bytes:
    """What `data` inflates to, reading at most `limit` + 1 bytes of it."""
    if compression == "zstd":
        import zstandard

        reader = zstandard.ZstdDecompressor().stream_reader(io.BytesIO(data))
        parts, total = [], 0
        while chunk := reader.read(min(1 << 20, limit + 1 - total)):
            parts.append(chunk)
            total += len(chunk)
            if total > limit:
                break
        return b"".join(parts)
    if compression == "lz4":
        import lz4.frame

        d = lz4.frame.LZ4FrameDecompressor()
        parts = [d.decompress(data, max_length=limit + 1)]
        total = len(parts[0])
        while total <= limit and not d.eof and d.needs_input is False:
            parts.append(d.decompress(b"", max_length=limit + 1 - total))
            total += len(parts[-1])
        return b"".join(parts)
    return data


class _Messages:
    """The messages counted so far, against MAX_MESSAGES and MAX_MESSAGE_BYTES."""

    def __init__(self, source: str) -> None:
        self.source, self.count = source, 0

    def add(self, length: int, at: int) -> None:
        self.count += 1
        if self.count > MAX_MESSAGES:
            raise InputError(
                f"more than {MAX_MESSAGES:,} messages, armcli's bound on a replay", file=self.source
            )
        if length > MAX_MESSAGE_BYTES:
            raise InputError(
                f"a message at byte {at} is {length} bytes, more than the "
                f"{MAX_MESSAGE_BYTES} a replay reads",
                file=self.source,
            )

    def walk(self, data: bytes, at: int) -> None:
        """Count the message records of a chunk's inflated records (opcode, length, body)."""
        pos, end = 0, len(data)
        while pos + 9 <= end:
            opcode, length = data[pos], int.from_bytes(data[pos + 1 : pos + 9], "little")
            if opcode == MESSAGE:
                self.add(length, at)
            pos += 9 + length


def _chunk(body: bytes, source: str, at: int, messages: _Messages) -> None:
    if len(body) < _CHUNK_HEAD.size:
        raise _bad(f"truncated chunk record at byte {at}", file=source)
    _, _, size, _, name_len = _CHUNK_HEAD.unpack_from(body)
    start = _CHUNK_HEAD.size
    name = body[start : start + name_len].decode("utf-8", "replace")
    if name not in COMPRESSIONS:
        raise _bad(f"chunk at byte {at}: unknown compression {name!r}", file=source)
    if size > MAX_CHUNK_BYTES:
        raise InputError(
            f"chunk at byte {at} declares {size} bytes, more than {MAX_CHUNK_BYTES}", file=source
        )
    (data_len,) = struct.unpack_from("<Q", body, start + name_len)
    data = body[start + name_len + 8 : start + name_len + 8 + data_len]
    if len(data) != data_len:
        raise _bad(f"truncated chunk data at byte {at}", file=source)
    try:
        records = _inflate(name, data, size)
    except Exception as exc:  # zstandard.ZstdError, RuntimeError from lz4: damaged data
        raise _bad(f"chunk at byte {at}: damaged {name} data ({exc})", file=source) from None
    real = len(records)
    if real != size:
        raise InputError(
            f"chunk at byte {at} inflates to {'more than ' if real > size else ''}{real} bytes, "
            f"not the {size} it declares",
            file=source,
        )
    messages.walk(records, at)


def check_chunks(fh: BinaryIO, source: str) -> None:
    """Walk the file's records (see the module docstring); InputError on the first lie."""
    fh.seek(0)
    if fh.read(len(MAGIC)) != MAGIC:
        raise _bad("not an MCAP file (no MCAP magic)", file=source)
    end = fh.seek(0, io.SEEK_END)
    at = fh.seek(len(MAGIC))
    messages = _Messages(source)
    for _ in range(MAX_RECORDS):
        head = fh.read(9)
        if len(head) < 9:
            break  # the magic at the end, or truncated: the reader reports which
        opcode, length = head[0], struct.unpack_from("<Q", head, 1)[0]
        if length > end - at - 9:
            raise _bad(f"record at byte {at} is longer than the file", file=source)
        if opcode == CHUNK and length > MAX_CHUNK_BYTES + 4096:  # compressed is never bigger
            raise _bad(f"chunk at byte {at} is more than {MAX_CHUNK_BYTES} bytes", file=source)
        if opcode == CHUNK:
            _chunk(fh.read(length), source, at, messages)
        else:
            if opcode == MESSAGE:
                messages.add(length, at)
            fh.seek(length, io.SEEK_CUR)
        at += 9 + length
        if opcode == FOOTER:
            break
    else:
        raise _bad(f"more than {MAX_RECORDS} records", file=source)
    fh.seek(0)
