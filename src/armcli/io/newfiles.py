"""Create a set of new files all-or-nothing, never replacing anything that exists.

`armcli init` writes into a directory the user owns, maybe their current one, so the
atomic writers in `io.files` (which replace outputs and swap whole directories) do not fit:
here an existing file is an error and the directory itself must never be swapped (a
shell sitting in it would be left in a stale copy). Files are written completely into
a hidden staging directory first; a new directory is then renamed into place in one
step, and into an existing one each file is hard-linked with no-replace semantics,
undoing the links already made if any fails.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Mapping
from pathlib import Path

from armcli.errors import BuildError, ExistingFileError, OutputRefusedError
from armcli.io.outdir import (
    mine,
    no_links_below,
    pid_alive,
    relative_inside,
    remove_entry,
    umask,
)

_STAGE_PREFIX = ".armcli-new-"  # + PID + "-": a killed run's stage is removed by the next


def _stage(parent: Path, files: Mapping[str, bytes]) -> Path:
    """A hidden directory in `parent` holding every file, flushed to disk."""
    stage = Path(tempfile.mkdtemp(dir=parent, prefix=f"{_STAGE_PREFIX}{os.getpid()}-"))
    os.chmod(stage, 0o777 & ~umask())  # mkdtemp makes 0700; a new project dir is ordinary
    for rel, data in files.items():
        path = stage / relative_inside(rel)
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "xb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return stage


def _clean_stale(parent: Path) -> None:
    """Remove this user's stages of killed runs (their PID is not alive)."""
    with contextlib.suppress(OSError):
        for entry in os.scandir(parent):
            pid = entry.name[len(_STAGE_PREFIX) :].split("-", 1)[0]
            if not entry.name.startswith(_STAGE_PREFIX) or not pid.isdigit() or not mine(entry):
                continue
            if not pid_alive(int(pid)):
                remove_entry(Path(entry.path))


def _refuse_existing(root: Path, files: Mapping[str, bytes]) -> None:
    if os.path.lexists(root) and not root.is_dir():
        raise ExistingFileError("exists and is not a directory", file=root)
    for rel in files:
        target = root / relative_inside(rel)
        if not no_links_below(root, relative_inside(rel).parent):
            raise OutputRefusedError(
                "a directory on the way is a symlink; armcli does not write new files "
                "through links (nothing was written)",
                file=target,
            )
        if os.path.lexists(target):
            raise ExistingFileError(
                "already exists; nothing was written (never overwritten)", file=target
            )


def _place(src: Path, dst: Path) -> None:
    """Hard-link src to dst, failing if dst exists; copy exclusively where links fail."""
    try:
        os.link(src, dst)
    except FileExistsError:
        raise
    except OSError:  # no hard links on this filesystem
        with open(src, "rb") as fin, open(dst, "xb") as fout:
            shutil.copyfileobj(fin, fout)
            fout.flush()
            os.fsync(fout.fileno())


def _link_into(root: Path, stage: Path, files: Mapping[str, bytes]) -> None:
    made_files: list[Path] = []
    made_dirs: list[Path] = []
    try:
        for rel in files:
            target = root / relative_inside(rel)
            for parent in reversed(target.relative_to(root).parents[:-1]):
                d = root / parent
                if not d.is_dir():
                    d.mkdir()
                    made_dirs.append(d)
            _place(stage / rel, target)
            made_files.append(target)
    except BaseException:
        for f in reversed(made_files):
            with contextlib.suppress(OSError):
                f.unlink()
        for d in reversed(made_dirs):
            with contextlib.suppress(OSError):
                d.rmdir()
        raise


def create_files(root: str | Path, files: Mapping[str, bytes]) -> list[Path]:
    """Write `files` (relative POSIX path -> bytes) under `root`, all or none.

    Returns:
        The written paths, in the order of `files`.

    Raises:
        ExistingFileError: a target (or `root` as a non-directory) exists; nothing written.
        BuildError: the filesystem refused a write; nothing left behind.
    """
    root = Path(root)
    _refuse_existing(root, files)
    try:
        if not os.path.lexists(root):
            root.parent.mkdir(parents=True, exist_ok=True)
            _clean_stale(root.parent)
            stage = _stage(root.parent, files)
            try:
                os.rename(stage, root)  # fails if root appeared meanwhile with content
            except OSError:
                shutil.rmtree(stage, ignore_errors=True)
                raise
        else:
            _clean_stale(root)
            stage = _stage(root, files)
            try:
                _link_into(root, stage, files)
            finally:
                shutil.rmtree(stage, ignore_errors=True)
    except FileExistsError as exc:
        raise ExistingFileError(
            "appeared while writing; nothing was written", file=exc.filename or root
        ) from None
    except OSError as exc:
        raise BuildError(f"{exc.filename or root}: cannot write: {exc.strerror}") from None
    return [root / relative_inside(rel) for rel in files]
