"""Mesh files checked before any mesh library loads them: decompressed size and triangle count.

trimesh opens compressed meshes by their content (bz2, gzip, zip, tar, zae, 3mf) and
decompresses them whole in memory: a 4.5 kB bz2 STL reached 3.0 GB, a 3 MB zip mesh
2.2 GB (issue 27). So every reader (mesh-derived inertia, check's collision model,
render, view, export, the ground contacts) first passes the file through
`check_mesh_payload`: compressed data is inflated here, streaming, and refused as soon
as it passes MAX_MESH_PAYLOAD_BYTES (the cap an uncompressed mesh has), and the triangle
count a binary STL, ASCII STL, OBJ or PLY declares is refused above MAX_MESH_TRIANGLES.
"""

from __future__ import annotations

import bz2
import io
import lzma
import re
import struct
import zipfile
import zlib
from collections.abc import Callable
from pathlib import Path

from armcli.errors import InputError
from armcli.io.userfile import read_regular

MAX_MESH_PAYLOAD_BYTES = 20_000_000  # decompressed, as much as an uncompressed mesh may hold
MAX_MESH_TRIANGLES = 2_000_000  # what render draws at most
MAX_ARCHIVE_MEMBERS = 1000
_CHUNK = 1 << 20
_PLY_FACES = re.compile(rb"^element\s+face\s+(\d+)\s*$", re.MULTILINE)


class _TooBigError(Exception):
    pass


def _inflate_streams(data: bytes, make: Callable[[], object], budget: int) -> bytes:
    """Every concatenated stream of bz2/xz/gzip `data`, refused past `budget` bytes."""
    out: list[bytes] = []
    total, rest = 0, data
    while rest:
        d = make()
        chunk = d.decompress(rest, budget + 1 - total)  # type: ignore[attr-defined]
        while True:
            total += len(chunk)
            out.append(chunk)
            if total > budget:
                raise _TooBigError
            if d.eof or getattr(d, "needs_input", False):  # type: ignore[attr-defined]
                break
            chunk = d.decompress(b"", budget + 1 - total)  # type: ignore[attr-defined]
        if not d.eof:  # type: ignore[attr-defined]
            break  # truncated: the loader will say so
        rest = d.unused_data  # type: ignore[attr-defined]
    return b"".join(out)


class _Gzip:
    """zlib's gzip decompressor with the bz2/lzma interface `_inflate_streams` uses."""

    def __init__(self) -> None:
        self._d = zlib.decompressobj(wbits=31)
        self.needs_input = False

    def decompress(self, data: bytes, max_length: int) -> bytes:
        out = self._d.decompress(data or self._d.unconsumed_tail, max_length)
        self.needs_input = not self._d.unconsumed_tail and not self._d.eof
        return out

    @property
    def eof(self) -> bool:
        return bool(self._d.eof)

    @property
    def unused_data(self) -> bytes:
        return bytes(self._d.unused_data)


def _unzip(data: bytes, budget: int) -> list[bytes]:
    """The members of a zip archive, refused past `budget` bytes in all (whatever they claim)."""
    out, total = [], 0
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        infos = zf.infolist()
        if len(infos) > MAX_ARCHIVE_MEMBERS:
            raise _TooBigError
        for info in infos:
            parts = []
            with zf.open(info) as member:
                while chunk := member.read(min(_CHUNK, budget + 1 - total)):
                    total += len(chunk)
                    parts.append(chunk)
                    if total > budget:
                        raise _TooBigError
            out.append(b"".join(parts))
    return out


def _payloads(data: bytes, budget: int) -> list[bytes]:
    """The data a loader would parse: `data` itself, or what its compression holds."""
    if data[:4] == b"PK\x03\x04":
        return _unzip(data, budget)
    if data[:3] == b"BZh":
        return [_inflate_streams(data, bz2.BZ2Decompressor, budget)]
    if data[:2] == b"\x1f\x8b":
        return [_inflate_streams(data, _Gzip, budget)]
    if data[:6] == b"\xfd7zXZ\x00":
        return [_inflate_streams(data, lzma.LZMADecompressor, budget)]
    return [data]


def declared_triangles(data: bytes) -> int:
    """The triangles a binary/ASCII STL, OBJ or PLY declares (0 when it is none of these)."""
    if len(data) >= 84:  # binary STL: an 80-byte header, a count, 50 bytes per triangle
        (n,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * n:
            return int(n)
    head = data[:512].lstrip().lower()
    if head.startswith(b"solid"):
        return data.count(b"endfacet")
    if head.startswith(b"ply"):
        found = _PLY_FACES.search(data[:4096])
        return int(found.group(1)) if found else 0
    return data.count(b"\nf ") + data.startswith(b"f ")  # OBJ faces (polygons count once)


def check_mesh_payload(path: str | Path, max_bytes: int, what: str = "mesh file") -> None:
    """Refuse a mesh whose decompressed data or declared triangle count is over the caps.

    Raises:
        InputError: naming the file and which cap it passes.
    """
    data = read_regular(path, max_bytes=max_bytes, what=what)
    try:
        payloads = _payloads(data, MAX_MESH_PAYLOAD_BYTES)
    except _TooBigError:
        raise InputError(
            f"{what} {path} decompresses to more than {MAX_MESH_PAYLOAD_BYTES} bytes"
            f" (or {MAX_ARCHIVE_MEMBERS} archive members); not loaded"
        ) from None
    except (OSError, EOFError, zipfile.BadZipFile, lzma.LZMAError, zlib.error, ValueError):
        raise InputError(f"{what} {path} is damaged compressed data; not loaded") from None
    triangles = sum(declared_triangles(p) for p in payloads)
    if triangles > MAX_MESH_TRIANGLES:
        raise InputError(
            f"{what} {path} declares {triangles} triangles, more than {MAX_MESH_TRIANGLES};"
            " not loaded"
        )
