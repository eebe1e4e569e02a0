"""Guarded output paths: where armcli may write, checked before anything is written.

`build -o` and `ros-package -o` replace a whole directory (io.files' staged swap).
A mistyped `-o "$UNSET/"` must not turn that into a copy of `/` (devices
included), so an output directory is refused when it is a filesystem root, a
mount point or the home directory, and when it already holds files but no
marker saying armcli wrote it (unless `--force`). The staging step carries
the old entries over as hard links (regular files are copied only when a link
is impossible), directories are walked and symlinks recreated as links (never
followed); a device, FIFO or socket is never opened: hard-linked, or refused. A symlinked output
directory is written through the link, and the old directory's permission bits
are kept. Single output files (`--output`, `--plot`, `-o x.png`) are checked up
front too, so one bad path fails the command before another file is written.
"""

from __future__ import annotations

import contextlib
import os
import pwd
import shutil
import stat
from collections.abc import Collection, Sequence
from pathlib import Path, PurePath, PurePosixPath

from armcli.errors import OutputRefusedError

MARKER_NAME = ".armcli-output"
MARKER_TEXT = (
    b"This directory is written by armcli (build, ros-package).\n"
    b"Its generated files are replaced on every run; other files are kept.\n"
)
STAGE_TAG = ".armcli-stage-"
MAX_CARRY_DEPTH = 32  # nesting bound of the old tree carried into the new version
_KINDS = {stat.S_IFCHR: "device", stat.S_IFBLK: "device", stat.S_IFIFO: "FIFO"}


def umask() -> int:
    """The process's file-creation mask (reading it means setting it; it is set back at once)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def relative_inside(rel: str) -> PurePosixPath:
    """`rel` as a path that stays inside the directory it is joined to; else refused.

    The one rule for every writer of a file set: relative, not empty, no `..` part.
    """
    p = PurePosixPath(rel)
    if p.is_absolute() or not p.parts or ".." in p.parts:
        raise OutputRefusedError(f"refusing to write outside the output directory: {rel!r}")
    return p


def _homes() -> set[Path]:
    homes = set()
    with contextlib.suppress(KeyError, RuntimeError):
        homes.add(Path.home().resolve())
    with contextlib.suppress(KeyError):
        homes.add(Path(pwd.getpwuid(os.getuid()).pw_dir).resolve())
    return homes


def _first_existing(path: Path) -> Path:
    p = path
    while not os.path.lexists(p) and p != p.parent:
        p = p.parent
    return p


def _check_parent(path: Path, field: str) -> None:
    anchor = _first_existing(path.parent)
    if not anchor.is_dir():
        raise OutputRefusedError(f"{anchor} is not a directory", file=path, field=field)


def resolve_output_dir(path: str | Path, *, force: bool = False, field: str = "out_dir") -> Path:
    """The real directory to write for `-o path`, or OutputRefusedError saying why not.

    Symlinks are resolved so that a linked output directory is updated through
    its link (the swap happens beside the target, the link stays a link).
    """
    given = Path(path)
    real = Path(os.path.realpath(given))
    if real == Path(real.anchor) or (real.is_dir() and os.path.ismount(real)):
        raise OutputRefusedError(
            "is a filesystem root or mount point; choose a directory inside it",
            file=given,
            field=field,
        )
    if real in _homes():
        raise OutputRefusedError(
            "is the home directory; choose a directory inside it", file=given, field=field
        )
    _check_parent(real, field)
    if os.path.lexists(real) and not real.is_dir():
        raise OutputRefusedError("exists and is not a directory", file=given, field=field)
    if real.is_dir() and not force and not (real / MARKER_NAME).is_file():
        with os.scandir(real) as entries:
            if next(entries, None) is not None:
                raise OutputRefusedError(
                    f"exists, is not empty and was not written by armcli (no {MARKER_NAME}); "
                    "choose a new or empty directory, or pass --force to add to it",
                    file=given,
                    field=field,
                )
    return real


def check_output_file(
    path: str | Path, field: str, inputs: Sequence[str | Path] = (), *, parents: bool = False
) -> None:
    """Refuse an output file path that cannot be written, before any output is written.

    `inputs`: the files the command reads; writing over one of them (`expand a.xacro -o
    a.xacro`, hard links and symlinks included) is refused (issue 27).
    `parents`: the file heads a set written together (export mjcf: model, scene, meshes),
    whose missing directories are created as `build -o` and `ros-package -o` create theirs.
    """
    p = Path(path)
    real = Path(os.path.realpath(p))
    for given in inputs:
        if os.path.realpath(given) == str(real) or (
            real.exists() and Path(given).exists() and os.path.samefile(given, real)
        ):
            raise OutputRefusedError(
                f"is the input file {given}; write elsewhere", file=p, field=field
            )
    if real.is_dir():
        raise OutputRefusedError("is a directory, expected a file path", file=p, field=field)
    if os.path.lexists(real) and not real.is_file():
        raise OutputRefusedError(
            "exists and is not a regular file (device, FIFO or socket)", file=p, field=field
        )
    if not real.parent.is_dir():  # a typo must not create directories (issue 20)
        _check_parent(real, field)
        if parents:
            return
        raise OutputRefusedError(
            f"directory {real.parent} does not exist; create it first", file=p, field=field
        )


def check_png_file(path: str | Path, field: str) -> None:
    """Refuse a plot path that does not end in .png (the plots are PNG; x.jpg would lie)."""
    p = Path(path)
    check_output_file(p, field)
    if p.suffix.lower() != ".png":
        raise OutputRefusedError(
            f"plots are written as PNG; name the file {p.stem or 'plot'}.png", file=p, field=field
        )


def clean_stale_stages(parent: Path, name: str) -> None:
    """Remove staging entries of any type left by killed armcli processes of this user."""
    prefix = f".{name}{STAGE_TAG}"
    with contextlib.suppress(FileNotFoundError, NotADirectoryError):
        for entry in list(os.scandir(parent)):
            if not entry.name.startswith(prefix) or not mine(entry):
                continue
            pid = entry.name[len(prefix) :].split("-", 1)[0]
            if pid.isdigit() and pid_alive(int(pid)):
                continue
            remove_entry(Path(entry.path))


def mine(entry: os.DirEntry[str]) -> bool:
    """Whether this user owns `entry` (not followed): only then may armcli remove it as stale.

    Another user's entry in a shared directory is never armcli's to delete (issue 42).
    """
    try:
        return entry.stat(follow_symlinks=False).st_uid == os.geteuid()
    except OSError:
        return False


def pid_alive(pid: int) -> bool:
    """Whether process `pid` exists: a staging entry of a live run is left alone."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_entry(path: Path) -> None:
    """Delete a file, link or directory tree armcli owns, also read-only directories."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    if not stat.S_ISDIR(st.st_mode):
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)
        return
    for dirpath, dirnames, _ in os.walk(path):  # make every directory writable first
        with contextlib.suppress(OSError):
            os.chmod(dirpath, 0o700)
        dirnames[:] = [d for d in dirnames if not os.path.islink(os.path.join(dirpath, d))]
    shutil.rmtree(path, ignore_errors=True)


def carry_entries(
    src: Path, dst: Path, skip: Collection[str], modes: list[tuple[Path, int]], depth: int = 0
) -> None:
    """Recreate `src`'s entries under `dst`: files hard-linked, links as links, dirs walked.

    Directory modes are collected in `modes` (applied after the new files are
    written, so a read-only directory can still receive them).
    """
    if depth > MAX_CARRY_DEPTH:
        raise OutputRefusedError(f"nested deeper than {MAX_CARRY_DEPTH} levels", file=src)
    with os.scandir(src) as it:
        entries = sorted(it, key=lambda e: e.name)
    for entry in entries:
        if entry.name in skip:
            continue
        st = entry.stat(follow_symlinks=False)
        target = dst / entry.name
        if stat.S_ISLNK(st.st_mode):
            os.symlink(os.readlink(entry.path), target)
        elif stat.S_ISDIR(st.st_mode):
            os.mkdir(target, 0o700)
            carry_entries(Path(entry.path), target, (), modes, depth + 1)
            modes.append((target, stat.S_IMODE(st.st_mode)))
        elif stat.S_ISREG(st.st_mode):
            _link_or_copy(entry.path, target)
        else:
            _link_special(entry.path, target, _KINDS.get(stat.S_IFMT(st.st_mode), "socket"))


def _link_special(src: str, dst: Path, kind: str) -> None:
    """Carry a device, FIFO or socket over by hard link; never open or copy it."""
    try:
        os.link(src, dst, follow_symlinks=False)
    except OSError as exc:
        raise OutputRefusedError(
            f"is a {kind} that cannot be hard-linked ({exc.strerror}); armcli never copies "
            "device files, FIFOs or sockets: move it out of the output directory",
            file=src,
        ) from None


def _link_or_copy(src: str, dst: Path) -> None:
    try:
        os.link(src, dst, follow_symlinks=False)
        return
    except OSError:
        pass
    fd = os.open(src, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # swapped for a FIFO since the scan
            raise OutputRefusedError("is not a regular file", file=src)
        with open(dst, "xb") as out:
            shutil.copyfileobj(fh, out)
    shutil.copystat(src, dst, follow_symlinks=False)


def no_links_below(root: Path, rel: PurePath) -> bool:
    """Whether every component of `rel` under `root` is a real entry (not a symlink)."""
    p = root
    for part in rel.parts:
        p = p / part
        if p.is_symlink():
            return False
    return True
