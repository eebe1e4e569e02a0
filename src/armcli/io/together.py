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

A kill before the journal exists leaves every target untouched (the staged files
are removed by the next write into that directory); a SIGKILL in the
microseconds between two renames leaves a journal, and the next write into any of
its directories (`finish_interrupted`) completes the renames, so the set ends all
new. Only a reader looking in that window, before the next armcli write, can see
a mix.

Targets are written through a symlink to the file it names (the link stays), and
an existing target keeps its permission bits. The parent directories must exist
unless `parents=True`.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path

from armcli.errors import BuildError, OutputRefusedError
from armcli.io.outdir import pid_alive, umask

TAG = ".armcli-set-"  # staged files `.NAME.armcli-set-PID-X.tmp`, journals `.armcli-set-PID-X.json`
_BLOCKED = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT}


def _owner_pid(name: str, prefix: str) -> int | None:
    """The PID in a staged or journal name after `prefix`, or None when it does not parse."""
    head = name[len(prefix) :].split("-", 1)[0]
    return int(head) if head.isdigit() else None


def target_path(path: str | Path) -> Path:
    """Where writing `path` lands: through a symlink to the file it names, else `path`."""
    p = Path(path)
    return Path(os.path.realpath(p)) if p.is_symlink() else p


def stage_file(target: Path, data: bytes, token: str) -> Path:
    """`data` in a flushed hidden temp file beside `target`, with the mode `target` will have."""
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}{token}", suffix=".tmp")
    try:
        try:
            mode = os.stat(target).st_mode & 0o7777  # keep an existing file's permission bits
        except FileNotFoundError:
            mode = 0o666 & ~umask()  # mkstemp makes 0600; a new output is an ordinary file
        os.fchmod(fd, mode)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return Path(tmp)


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


def _write_journal(directory: Path, name: str, pairs: list[tuple[str, str]]) -> Path:
    journal = directory / name
    tmp = directory / f"{name}.part"
    with open(tmp, "w", encoding="utf-8") as fh:
        json.dump(pairs, fh)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, journal)
    _fsync_dir(directory)
    return journal


def _commit(pairs: list[tuple[str, str]], journals: list[Path]) -> None:
    for staged, target in pairs:
        if os.path.lexists(staged):
            os.replace(staged, target)
    for d in {Path(t).parent for _, t in pairs}:
        _fsync_dir(d)
    for j in journals:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(j)


def finish_interrupted(directory: Path) -> None:
    """Complete the sets a killed armcli left half-renamed; remove its orphan staged files."""
    try:
        names = os.listdir(directory)
    except OSError:
        return
    pending: set[str] = set()
    for name in sorted(names):
        pid = _owner_pid(name, TAG)
        if not name.endswith(".json") or pid is None or pid_alive(pid):
            continue
        try:
            pairs = [(str(s), str(t)) for s, t in json.loads((directory / name).read_text())]
        except (OSError, ValueError, TypeError):
            pairs = []
        others = [Path(t).parent / name for _, t in pairs]
        _commit(pairs, [directory / name, *others])  # every staged file was complete
        pending |= {Path(s).name for s, _ in pairs}
    for name in names:
        pid = _staged_pid(name)
        if pid is not None and name not in pending and not pid_alive(pid):
            with contextlib.suppress(OSError):
                os.unlink(directory / name)


def _staged_pid(name: str) -> int | None:
    """The PID of a staged file `.TARGET.armcli-set-PID-X.tmp` or journal part, else None."""
    if not name.startswith(".") or TAG not in name or not name.endswith((".tmp", ".part")):
        return None
    return _owner_pid(name[name.index(TAG) :], TAG)


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
    directories = sorted({t.parent for t in targets})
    for d in directories:
        finish_interrupted(d)
    token = f"{TAG}{os.getpid()}-"
    staged: list[Path] = []
    try:
        for t, data in zip(targets, files.values(), strict=True):
            staged.append(stage_file(t, data, token))
    except OSError as exc:
        for s in staged:
            with contextlib.suppress(OSError):
                os.unlink(s)
        raise BuildError(f"{exc.filename or given[0]}: cannot write: {_why(exc)}") from None
    pairs = [(str(s), str(t)) for s, t in zip(staged, targets, strict=True)]
    try:
        with _signals_held():
            journals = []
            if len(pairs) > 1:
                name = f"{token}{os.urandom(4).hex()}.json"
                journals = [_write_journal(d, name, pairs) for d in directories]
            _commit(pairs, journals)
    except OSError as exc:  # journals left behind: the next write completes the set
        raise BuildError(f"{exc.filename or given[0]}: cannot write: {_why(exc)}") from None
    return given


def _why(exc: OSError) -> str:
    return exc.strerror or str(exc)
