"""Several output files in any directories, replaced together: all new or all old.

`simulate --output states.csv --plot tracking.png` (and any command writing more
than one file that is not one directory tree; `files.write_tree_atomic` swaps a
whole tree) used to write each file as soon as it was ready: a run killed while
drawing the plot left a new CSV beside an old plot. Here every file is staged
completely (written and fsynced to a hidden temporary file beside its target)
before any target changes. Then a journal naming each (staged file, target) pair
is written into every target directory, the targets are renamed in one after
another with SIGINT, SIGTERM, SIGHUP and SIGQUIT blocked, and the journals are
removed.

A kill before the journals exist leaves every target untouched (the staged files
are removed by the next write into that directory); a SIGKILL in the microseconds
between two renames leaves journals, and the next write into each of their directories
completes that directory's renames (`io.journal`: a journal is replayed only when it is
provably armcli's own and names nothing outside its directory; anything else is left
alone and reported as a warning). Only a reader looking in that window, before the next
armcli write there, can see a mix.

Targets are written through a symlink to the file it names (the link stays), and
an existing target keeps its permission bits. The parent directories must exist
unless `parents=True`.
"""

from __future__ import annotations

import contextlib
import os
import signal
import warnings
from collections.abc import Iterator, Mapping
from pathlib import Path

from armcli.errors import ArmcliWarning, BuildError, OutputRefusedError
from armcli.io.journal import TAG, SetId, recover, write_journal
from armcli.io.outdir import umask

__all__ = ["TAG", "finish_interrupted", "stage_file", "target_path", "write_files_together"]
_BLOCKED = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT}


def target_path(path: str | Path) -> Path:
    """Where writing `path` lands: through a symlink to the file it names, else `path`."""
    p = Path(path)
    return Path(os.path.realpath(p)) if p.is_symlink() else p


def stage_file(target: Path, data: bytes, name: str) -> Path:
    """`data` in a new flushed file `name` beside `target`, with the mode `target` will have.

    Created with O_EXCL and O_NOFOLLOW: it is a file this process made, never an existing one.
    """
    tmp = target.parent / name
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC
    fd = os.open(tmp, flags, 0o600)
    try:
        try:
            mode = os.stat(target).st_mode & 0o7777  # keep an existing file's permission bits
        except FileNotFoundError:
            mode = 0o666 & ~umask()  # a new output is an ordinary file
        os.fchmod(fd, mode)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return tmp


def _fsync_dir(directory: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Hold the catchable termination signals (main thread only) while the set is renamed."""
    try:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, _BLOCKED)
    except (ValueError, OSError):  # not available here: rename anyway
        yield
        return
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _commit(pairs: list[tuple[Path, Path]], journals: list[Path]) -> None:
    for staged, target in pairs:
        os.replace(staged, target)
    for d in {t.parent for _, t in pairs}:
        _fsync_dir(d)
    for j in journals:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(j)


def finish_interrupted(directory: Path) -> None:
    """Complete this user's sets killed armcli runs left in `directory`; warn about the rest.

    Each report is one ArmcliWarning line (the CLI prints it as `warning: ...`).
    """
    for line in recover(directory):
        warnings.warn(line, ArmcliWarning, stacklevel=3)


def write_files_together(files: Mapping[Path, bytes], *, parents: bool = False) -> list[Path]:
    """Write every file of `files` (target path -> bytes) so that all change or none.

    Returns the targets as given. BuildError when a file cannot be written (nothing
    changed then); OutputRefusedError for a missing parent directory unless `parents`.
    """
    given = [Path(p) for p in files]
    targets = [target_path(p) for p in given]
    if len(set(targets)) != len(targets):
        raise OutputRefusedError("the same file is named twice", file=given[0])
    for g, t in zip(given, targets, strict=True):
        if not t.parent.is_dir():
            if not parents:
                raise OutputRefusedError(f"directory {t.parent} does not exist", file=g)
            t.parent.mkdir(parents=True, exist_ok=True)
        if t.is_dir():
            raise BuildError(f"{g}: is a directory, cannot write a file there")
    targets = [Path(os.path.realpath(t.parent)) / t.name for t in targets]  # one name per dir
    if len(set(targets)) != len(targets):
        raise OutputRefusedError("the same file is named twice", file=given[0])
    directories = sorted({t.parent for t in targets})
    for d in directories:
        finish_interrupted(d)
    set_id = SetId.new()
    staged: list[Path] = []
    try:
        for i, (t, data) in enumerate(zip(targets, files.values(), strict=True)):
            staged.append(stage_file(t, data, set_id.staged(i)))
    except OSError as exc:
        for s in staged:
            with contextlib.suppress(OSError):
                os.unlink(s)
        raise BuildError(f"{exc.filename or given[0]}: cannot write: {_why(exc)}") from None
    pairs = list(zip(staged, targets, strict=True))
    try:
        with _signals_held():
            journals = []
            if len(pairs) > 1:
                for d in directories:
                    mine = [(i, t.name) for i, t in enumerate(targets) if t.parent == d]
                    journals.append(write_journal(d, set_id, mine))
            _commit(pairs, journals)
    except OSError as exc:  # journals left behind: the next write completes the set
        raise BuildError(f"{exc.filename or given[0]}: cannot write: {_why(exc)}") from None
    return given


def _why(exc: OSError) -> str:
    return exc.strerror or str(exc)
