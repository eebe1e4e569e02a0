"""Atomic file output: a reader never sees a half-written file or a half-swapped set.

Single files: write to a temporary file in the target directory, fsync, then
`os.replace` (atomic on POSIX). File sets: every file is first written and
fsynced under temporary names; only when all of them exist are they renamed
into place, so a crash during generation leaves the previous outputs intact.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path, PurePosixPath

from armcli.errors import BuildError


def _safe_relpath(rel: str) -> PurePosixPath:
    """Reject names that would escape the output directory."""
    p = PurePosixPath(rel)
    if p.is_absolute() or not p.parts or any(part in ("..", "") for part in p.parts):
        raise BuildError(f"refusing to write outside the output directory: {rel!r}")
    return p


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _write_temp(directory: Path, name: str, data: bytes) -> Path:
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{name}.", suffix=".tmp")
    try:
        os.fchmod(fd, 0o666 & ~_umask())  # mkstemp makes 0600; outputs are ordinary files
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return Path(tmp)


def write_file_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write `data` to `path` atomically (temp file in the same directory + rename)."""
    target = Path(path)
    payload = data.encode("utf-8") if isinstance(data, str) else data
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.is_dir():
            raise BuildError(f"{target}: is a directory, cannot write a file there")
        tmp = _write_temp(target.parent, target.name, payload)
        try:
            os.replace(tmp, target)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    except OSError as exc:
        raise BuildError(f"{target}: cannot write: {exc.strerror}") from None
    return target


def write_tree_atomic(out_dir: str | Path, files: Mapping[str, bytes | str]) -> list[Path]:
    """Write a set of files under `out_dir` all-or-nothing; returns the written paths.

    Unchanged files are left untouched (same bytes, same mtime) so that
    rebuilding is a no-op for tools that watch timestamps.
    """
    root = Path(out_dir)
    staged: list[tuple[Path, Path]] = []
    try:
        for rel in sorted(files):
            relp = _safe_relpath(rel)
            data = files[rel]
            payload = data.encode("utf-8") if isinstance(data, str) else data
            target = root.joinpath(*relp.parts)
            if target.is_file() and target.read_bytes() == payload:
                continue
            if target.is_dir():
                raise BuildError(f"{target}: is a directory, cannot write a file there")
            target.parent.mkdir(parents=True, exist_ok=True)
            staged.append((_write_temp(target.parent, target.name, payload), target))
        for tmp, target in staged:
            os.replace(tmp, target)
        staged = []
    except OSError as exc:
        raise BuildError(f"{out_dir}: cannot write: {exc.strerror} ({exc.filename})") from None
    finally:
        for tmp, _ in staged:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    return [root.joinpath(*_safe_relpath(r).parts) for r in sorted(files)]
