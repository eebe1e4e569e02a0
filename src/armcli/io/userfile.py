"""Reading a user's input file: regular files only, size-capped, refused before opening.

A FIFO given as a spec blocks `open()` forever, a device such as /dev/zero
never ends, and opening some devices has side effects, so the file type is
checked with `stat` before the file is opened, and again on the open
descriptor (O_NONBLOCK, so a FIFO swapped in between cannot block either).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import BinaryIO

from armcli.errors import InputError

_KINDS = {
    stat.S_IFDIR: "a directory",
    stat.S_IFIFO: "a FIFO",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFSOCK: "a socket",
}


def _refuse_special(mode: int, path: Path, what: str) -> None:
    if not stat.S_ISREG(mode):
        kind = _KINDS.get(stat.S_IFMT(mode), "not a regular file")
        raise InputError(f"is {kind}, expected a regular {what}", file=path)


def check_regular(path: str | Path, what: str = "file") -> int:
    """The size [bytes] of `path` if it is a regular file (symlinks followed), else InputError."""
    p = Path(path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise InputError(f"{what} not found", file=p) from None
    except OSError as exc:
        raise InputError(f"cannot read {what}: {exc.strerror}", file=p) from None
    _refuse_special(st.st_mode, p, what)
    return st.st_size


def open_regular(path: str | Path, *, max_bytes: int, what: str = "file") -> BinaryIO:
    """A binary stream of a regular file of at most `max_bytes` (checked before opening)."""
    p = Path(path)
    size = check_regular(p, what)
    if size > max_bytes:
        raise InputError(f"{what} is {size} bytes, larger than the {max_bytes}-byte cap", file=p)
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as exc:
        raise InputError(f"cannot read {what}: {exc.strerror}", file=p) from None
    fh = os.fdopen(fd, "rb")
    try:
        _refuse_special(os.fstat(fd).st_mode, p, what)  # replaced since the stat
    except BaseException:
        fh.close()
        raise
    return fh


def read_regular(path: str | Path, *, max_bytes: int, what: str = "file") -> bytes:
    """The bytes of a regular file of at most `max_bytes`; InputError otherwise."""
    p = Path(path)
    with open_regular(p, max_bytes=max_bytes, what=what) as fh:
        try:
            raw = fh.read(max_bytes + 1)
        except OSError as exc:
            raise InputError(f"cannot read {what}: {exc.strerror}", file=p) from None
    if len(raw) > max_bytes:
        raise InputError(f"{what} is larger than the {max_bytes}-byte cap", file=p)
    return raw
