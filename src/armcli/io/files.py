"""Atomic file output: a reader never sees a half-written file or a half-swapped set.

Single files: write to a temporary file in the target directory, fsync, then
`os.replace` (atomic on POSIX). File sets: the complete new directory is staged
next to the target (unrelated files already there are hard-linked in) and then
exchanged with the old one in one `renameat2(RENAME_EXCHANGE)` call, so the
directory is at every instant either entirely old or entirely new. Where the
kernel or filesystem lacks the exchange, files are renamed in one by one after
all of them were written (a kill can then only land in that microsecond window).
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import shutil
import tempfile
from collections.abc import Mapping
from pathlib import Path, PurePosixPath

from armcli.errors import BuildError

_AT_FDCWD = -100
_RENAME_EXCHANGE = 2
_STAGE_TAG = ".armcli-stage-"


def _safe_relpath(rel: str) -> PurePosixPath:
    """Reject names that would escape the output directory."""
    p = PurePosixPath(rel)
    if p.is_absolute() or not p.parts or any(part in ("..", "", ".") for part in p.parts):
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


def _payload(data: bytes | str) -> bytes:
    return data.encode("utf-8") if isinstance(data, str) else data


def write_file_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write `data` to `path` atomically (temp file in the same directory + rename)."""
    target = Path(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.is_dir():
            raise BuildError(f"{target}: is a directory, cannot write a file there")
        tmp = _write_temp(target.parent, target.name, _payload(data))
        try:
            os.replace(tmp, target)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    except OSError as exc:
        raise BuildError(f"{target}: cannot write: {exc.strerror}") from None
    return target


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two paths (Linux renameat2); False where unsupported."""
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return False
    rc = fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    return bool(rc == 0)


def _clean_stale_stages(parent: Path, name: str) -> None:
    """Remove staging directories left by armcli processes that were killed."""
    for stage in parent.glob(f".{name}{_STAGE_TAG}*"):
        pid = stage.name.rsplit("-", 2)[-2]
        alive = pid.isdigit() and _pid_alive(int(pid))
        if not alive:
            shutil.rmtree(stage, ignore_errors=True)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _link_or_copy(src: str, dst: str) -> None:
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


def _stage(root: Path, files: Mapping[str, bytes]) -> Path:
    """A complete new version of `root` beside it: untouched entries linked, files written."""
    stage = Path(
        tempfile.mkdtemp(dir=root.parent, prefix=f".{root.name}{_STAGE_TAG}{os.getpid()}-")
    )
    try:
        _populate(stage, root, files)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    return stage


def _populate(stage: Path, root: Path, files: Mapping[str, bytes]) -> None:
    os.chmod(stage, 0o777 & ~_umask())
    if root.is_dir():
        for entry in os.scandir(root):
            if entry.name in files:
                continue
            if entry.is_dir(follow_symlinks=False):
                shutil.copytree(
                    entry.path, stage / entry.name, symlinks=True, copy_function=_link_or_copy
                )
            elif entry.is_symlink():
                os.symlink(os.readlink(entry.path), stage / entry.name)
            else:
                _link_or_copy(entry.path, str(stage / entry.name))
    for rel, data in files.items():
        target = stage / rel
        if target.is_dir():
            raise BuildError(f"{root / rel}: is a directory, cannot write a file there")
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.exists() or target.is_symlink():
            target.unlink()  # a hard link to the old file: never write through it
        os.replace(_write_temp(target.parent, target.name, data), target)


def _unchanged(root: Path, files: Mapping[str, bytes]) -> bool:
    return all((root / r).is_file() and (root / r).read_bytes() == d for r, d in files.items())


def write_tree_atomic(out_dir: str | Path, files: Mapping[str, bytes | str]) -> list[Path]:
    """Write a set of files under `out_dir` all-or-nothing; returns the written paths.

    A rebuild with identical content touches nothing (same bytes, same mtimes).
    """
    root = Path(out_dir)
    payloads = {str(_safe_relpath(r)): _payload(d) for r, d in sorted(files.items())}
    paths = [root.joinpath(*PurePosixPath(r).parts) for r in payloads]
    try:
        root.parent.mkdir(parents=True, exist_ok=True)
        if root.exists() and not root.is_dir():
            raise BuildError(f"{root}: exists and is not a directory")
        for p in paths:
            if p.is_dir():
                raise BuildError(f"{p}: is a directory, cannot write a file there")
        if root.is_dir() and _unchanged(root, payloads):
            return paths
        _clean_stale_stages(root.parent, root.name)
        stage = _stage(root, payloads)
        try:
            if not root.exists():
                os.rename(stage, root)
            elif _exchange(stage, root):
                shutil.rmtree(stage, ignore_errors=True)  # `stage` now holds the old tree
            else:
                _replace_one_by_one(stage, root, payloads)
        finally:
            if stage.exists():
                shutil.rmtree(stage, ignore_errors=True)
    except OSError as exc:
        raise BuildError(f"{root}: cannot write: {exc.strerror} ({exc.filename})") from None
    return paths


def _replace_one_by_one(stage: Path, root: Path, files: Mapping[str, bytes]) -> None:
    for rel in files:
        target = root / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(stage / rel, target)
