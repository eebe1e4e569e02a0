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

import ctypes
import os
import stat
import tempfile
from collections.abc import Mapping
from pathlib import Path, PurePosixPath

from armcli.errors import BuildError, OutputRefusedError
from armcli.io.outdir import (
    MARKER_NAME,
    MARKER_TEXT,
    STAGE_TAG,
    carry_entries,
    clean_stale_stages,
    no_links_below,
    relative_inside,
    remove_entry,
    resolve_output_dir,
    umask,
)
from armcli.io.together import stage_file, write_files_together

_AT_FDCWD = -100
_RENAME_EXCHANGE = 2


def _payload(data: bytes | str) -> bytes:
    return data.encode("utf-8") if isinstance(data, str) else data


def write_file_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write `data` to `path` atomically (temp file in the same directory + rename).

    Missing parent directories are created (commands check their output paths first,
    `outdir.check_output_file`); a symlink is written through and an existing file keeps
    its permission bits (`together.write_files_together`, the one staging writer).
    """
    return write_files_together({Path(path): _payload(data)}, parents=True)[0]


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two paths (Linux renameat2); False where unsupported."""
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return False
    rc = fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    return bool(rc == 0)


def _stage(root: Path, files: Mapping[str, bytes]) -> Path:
    """A complete new version of `root` beside it: untouched entries linked, files written."""
    stage = Path(tempfile.mkdtemp(dir=root.parent, prefix=f".{root.name}{STAGE_TAG}{os.getpid()}-"))
    try:
        _populate(stage, root, files)
    except BaseException:
        remove_entry(stage)
        raise
    return stage


def _populate(stage: Path, root: Path, files: Mapping[str, bytes]) -> None:
    modes: list[tuple[Path, int]] = []
    if root.is_dir():
        carry_entries(root, stage, {r for r in files if "/" not in r}, modes)
    for rel, data in files.items():
        target = stage / rel
        if not no_links_below(stage, PurePosixPath(rel).parent):
            raise OutputRefusedError(
                f"{rel}: a directory on the way is a symlink; armcli does not write through "
                "links inside the output directory",
                file=root,
            )
        if target.is_dir() and not target.is_symlink():
            raise BuildError(f"{root / rel}: is a directory, cannot write a file there")
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.exists() or target.is_symlink():
            target.unlink()  # a hard link to the old file: never write through it
        tmp = stage_file(target, data, f".{os.urandom(8).hex()}.tmp")  # a private stage dir
        os.replace(tmp, target)  # target unlinked above: a new file's mode
    for path, mode in modes:  # innermost first: read-only directories receive files first
        os.chmod(path, mode)
    keep = stat.S_IMODE(os.stat(root).st_mode) if root.is_dir() else 0o777 & ~umask()
    os.chmod(stage, keep)


def _unchanged(root: Path, files: Mapping[str, bytes]) -> bool:
    for rel, data in files.items():
        path = root / rel
        if not no_links_below(root, PurePosixPath(rel)):
            return False
        try:
            st = os.lstat(path)
        except OSError:
            return False
        if not stat.S_ISREG(st.st_mode) or st.st_size != len(data) or path.read_bytes() != data:
            return False
    return True


def write_tree_atomic(
    out_dir: str | Path, files: Mapping[str, bytes | str], *, force: bool = False
) -> list[Path]:
    """Write a set of files under `out_dir` all-or-nothing; returns the written paths.

    `out_dir` must pass outdir.resolve_output_dir (not `/`, not home, not a
    foreign non-empty directory unless `force`); armcli's marker file is added.
    A rebuild with identical content touches nothing (same bytes, same mtimes).
    """
    given = Path(out_dir)
    payloads = {str(relative_inside(r)): _payload(d) for r, d in sorted(files.items())}
    paths = [given.joinpath(*PurePosixPath(r).parts) for r in payloads]
    payloads[MARKER_NAME] = MARKER_TEXT
    root = resolve_output_dir(given, force=force)
    try:
        for rel in payloads:
            if (root / rel).is_dir() and not (root / rel).is_symlink():
                raise BuildError(f"{given / rel}: is a directory, cannot write a file there")
        if root.is_dir() and _unchanged(root, payloads):
            return paths
        root.parent.mkdir(parents=True, exist_ok=True)
        clean_stale_stages(root.parent, root.name)
        if given.is_symlink():  # left by versions that swapped the link itself
            clean_stale_stages(given.parent, given.name)
        stage = _stage(root, payloads)
        try:
            if not root.exists():
                os.rename(stage, root)
            elif _exchange(stage, root):
                pass  # `stage` now holds the old tree, removed below
            else:
                _replace_one_by_one(stage, root, payloads)
        finally:
            remove_entry(stage)
    except OSError as exc:
        raise BuildError(f"{given}: cannot write: {_why(exc)}") from None
    return paths


def _why(exc: OSError) -> str:
    """`strerror (file)` without the `(None)` of errors that carry no file name."""
    text = exc.strerror or str(exc)
    return f"{text} ({exc.filename})" if exc.filename else text


def _replace_one_by_one(stage: Path, root: Path, files: Mapping[str, bytes]) -> None:
    for rel in files:
        target = root / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(stage / rel, target)
