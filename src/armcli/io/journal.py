"""The recovery journal of a file set, and what a later write may do with a stale one.

`together.write_files_together` renames several staged files over their targets; a
SIGKILL between two renames leaves a journal so that the next write can finish the set.
The journal lies in a directory other people may write to, so it is untrusted input
(issue 42: a planted journal made armcli rename a payload over `~/.bashrc`, move a
secret into the directory, delete `calibration_4242-left.json`, hang on a FIFO and read
`/dev/zero` until memory ran out). The rule: armcli only ever renames or deletes what
armcli created, and a journal is never followed outside its own directory.

- One journal per directory, named `.armcli-set-PID-KEY.json` (KEY: 16 random hex
  digits), created with O_EXCL under a `.part` name and renamed into place; it lists
  `[index, name]` pairs: each target is a plain name in the journal's directory, and
  its staged file is `.armcli-set-PID-KEY-INDEX.tmp` beside it, a name the journal's
  own name fixes. No path in a journal is ever opened.
- A journal is replayed only when its process is dead, it is a regular file of this user
  with one link and at most MAX_JOURNAL_BYTES (checked on the open descriptor: opened
  with O_NOFOLLOW | O_NONBLOCK, so a symlink or FIFO is refused and nothing blocks), its
  content is exactly that format, and every staged file it names is also a regular file
  of this user with one link. Everything is done relative to the directory's descriptor.
- A journal failing any of this is left alone with its staged files and reported in one
  warning line per directory; a killed run's staged and `.part` files (exact names, this
  user's regular files, dead process) are removed. Nothing else is touched: a name that
  merely looks similar (`calibration_4242-left.json`) is not armcli's.

What a journal cannot do: complete a set across directories (a write into each directory
completes its own files; until then a SIGKILLed set may stay mixed there), nor protect
against another process of the same user, which may rename files itself anyway.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path

from armcli.io.outdir import pid_alive

TAG = ".armcli-set-"
MAX_JOURNAL_BYTES = 64 * 1024  # a set of a few files takes ~100 bytes per file
MAX_SET_FILES = 1000  # files of one set in one directory
MAX_REPORTED = 1  # journals named in the warning line; the rest are counted
_ID = r"([1-9][0-9]{0,6})-([0-9a-f]{16})"  # PIDs stay below 2**22 (Linux's largest pid_max)
_JOURNAL = re.compile(rf"\.armcli-set-{_ID}\.json")
_LEFTOVER = re.compile(rf"\.armcli-set-{_ID}(?:-(?:0|[1-9][0-9]{{0,3}})\.tmp|\.part)")


@dataclass(frozen=True)
class SetId:
    """The identity of one set: the writing process and a random key, in every name it uses."""

    pid: int
    key: str

    @classmethod
    def new(cls) -> SetId:
        """A fresh identity for this process (the key keeps names unguessable and unique)."""
        return cls(os.getpid(), os.urandom(8).hex())

    def staged(self, index: int) -> str:
        """The staged file of target `index`, in the target's directory."""
        return f"{TAG}{self.pid}-{self.key}-{index}.tmp"

    @property
    def journal(self) -> str:
        """The journal's name in each directory of the set."""
        return f"{TAG}{self.pid}-{self.key}.json"

    @property
    def part(self) -> str:
        """The journal while it is being written."""
        return f"{TAG}{self.pid}-{self.key}.part"


class UntrustedError(Exception):
    """A journal (or a file it names) that armcli cannot prove its own: why, in words."""


def write_journal(directory: Path, set_id: SetId, entries: list[tuple[int, str]]) -> Path:
    """Write the journal of `entries` (index, target name) into `directory`, durably."""
    data = json.dumps([[i, name] for i, name in entries]).encode("utf-8")
    dfd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC
        fd = os.open(set_id.part, flags, 0o600, dir_fd=dfd)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.rename(set_id.part, set_id.journal, src_dir_fd=dfd, dst_dir_fd=dfd)
        os.fsync(dfd)
    finally:
        os.close(dfd)
    return directory / set_id.journal


def recover(directory: Path) -> list[str]:
    """Finish the sets killed armcli runs of this user left in `directory`; what to report.

    Returns at most two lines: the sets completed, and the journals left alone.
    """
    try:
        dfd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except OSError:
        return []
    try:
        names = sorted(os.listdir(dfd))
        done, refused, held = [], [], set()
        for name in names:
            m = _JOURNAL.fullmatch(name)
            if m is None or not _dead(int(m[1])):
                continue
            set_id = SetId(int(m[1]), m[2])
            try:
                done += _replay(dfd, set_id)
            except UntrustedError as exc:
                refused.append(f"{name}: {exc}")
                held.add(set_id)
            except OSError as exc:  # raced away, or the directory refuses: keep its files
                refused.append(f"{name}: {exc.strerror}")
                held.add(set_id)
        _remove_leftovers(dfd, names, held)
    finally:
        os.close(dfd)
    return _report(directory, done, refused)


def _dead(pid: int) -> bool:
    return pid != os.getpid() and not pid_alive(pid)


def _report(directory: Path, done: list[str], refused: list[str]) -> list[str]:
    lines = []
    if done:
        lines.append(
            f"{directory}: completed the files a killed armcli run left half-written: "
            f"{', '.join(done)}"
        )
    if refused:
        more = len(refused) - MAX_REPORTED
        shown = "; ".join(refused[:MAX_REPORTED]) + (f" (and {more} more)" if more > 0 else "")
        lines.append(
            f"{directory}: left alone, not armcli's own recovery journal: {shown}; "
            "remove it if no armcli run is writing here"
        )
    return lines


def _replay(dfd: int, set_id: SetId) -> list[str]:
    """Rename the journal's staged files over its targets (all checked first), drop it."""
    entries = _read(dfd, set_id.journal)
    moves = []
    for index, target in entries:
        staged = set_id.staged(index)
        try:
            st = os.stat(staged, dir_fd=dfd, follow_symlinks=False)
        except FileNotFoundError:
            continue  # renamed before the kill
        _own_file(st, f"its staged file {staged}")
        with contextlib.suppress(FileNotFoundError):
            if stat.S_ISDIR(os.stat(target, dir_fd=dfd, follow_symlinks=False).st_mode):
                raise UntrustedError(f"its target {target!r} is a directory")
        moves.append((staged, target))
    for staged, target in moves:
        os.rename(staged, target, src_dir_fd=dfd, dst_dir_fd=dfd)
    os.fsync(dfd)
    os.unlink(set_id.journal, dir_fd=dfd)
    return [target for _, target in moves]


def _own_file(st: os.stat_result, what: str) -> None:
    """UntrustedError unless `st` is a regular file of this user with no other name."""
    if stat.S_ISLNK(st.st_mode):
        raise UntrustedError(f"{what} is a symbolic link")
    if not stat.S_ISREG(st.st_mode):
        raise UntrustedError(f"{what} is not a regular file")
    if st.st_uid != os.geteuid():
        raise UntrustedError(f"{what} belongs to another user (uid {st.st_uid})")
    if st.st_nlink != 1:
        raise UntrustedError(f"{what} has other names (hard links)")


def _read(dfd: int, name: str) -> list[tuple[int, str]]:
    """The journal's entries; UntrustedError unless it is exactly what `write_journal` writes."""
    _own_file(os.stat(name, dir_fd=dfd, follow_symlinks=False), "it")  # before any open
    try:
        fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, dir_fd=dfd)
    except OSError as exc:
        raise UntrustedError(
            "it is a symbolic link"
            if exc.errno == errno.ELOOP
            else f"it cannot be read: {exc.strerror}"
        ) from None
    try:
        st = os.fstat(fd)  # the file opened, not the one looked at: swapped meanwhile?
        _own_file(st, "it")
        if st.st_size > MAX_JOURNAL_BYTES:
            raise UntrustedError(f"it is larger than {MAX_JOURNAL_BYTES} bytes")
        data = os.read(fd, MAX_JOURNAL_BYTES + 1)
    finally:
        os.close(fd)
    if len(data) > MAX_JOURNAL_BYTES:
        raise UntrustedError(f"it is larger than {MAX_JOURNAL_BYTES} bytes")
    try:
        doc = json.loads(data.decode("utf-8"))
    except ValueError:
        raise UntrustedError("it is not JSON armcli wrote") from None
    return _entries(doc)


def _entries(doc: object) -> list[tuple[int, str]]:
    if not isinstance(doc, list) or not 0 < len(doc) <= MAX_SET_FILES:
        raise UntrustedError(f"it is not a list of 1 to {MAX_SET_FILES} [index, name] pairs")
    out: list[tuple[int, str]] = []
    for item in doc:
        ok = isinstance(item, list) and len(item) == 2 and type(item[0]) is int
        if not ok or not 0 <= item[0] < 10 * MAX_SET_FILES or not isinstance(item[1], str):
            raise UntrustedError("it is not a list of [index, name] pairs")
        if not plain_name(item[1]):
            raise UntrustedError(f"its target {item[1]!r} is not a file name in this directory")
        out.append((item[0], item[1]))
    if len({i for i, _ in out}) != len(out) or len({n for _, n in out}) != len(out):
        raise UntrustedError("it names a file twice")
    return out


def plain_name(name: str) -> bool:
    """Whether `name` is one entry of a directory: no `/`, not `.` or `..`, not armcli's own."""
    try:
        size = len(os.fsencode(name))
    except UnicodeError:
        return False
    if name in ("", ".", "..") or "/" in name or "\0" in name or size > 255:
        return False
    return _JOURNAL.fullmatch(name) is None and _LEFTOVER.fullmatch(name) is None


def _remove_leftovers(dfd: int, names: list[str], held: set[SetId]) -> None:
    """Delete staged and `.part` files of killed runs: exact names, this user's regular files."""
    for name in names:
        m = _LEFTOVER.fullmatch(name)
        if m is None or SetId(int(m[1]), m[2]) in held or not _dead(int(m[1])):
            continue
        try:
            _own_file(os.stat(name, dir_fd=dfd, follow_symlinks=False), name)
        except (UntrustedError, OSError):
            continue  # another user's, a link, a FIFO: not armcli's to delete
        with contextlib.suppress(FileNotFoundError):
            os.unlink(name, dir_fd=dfd)
