"""Guarded output directories and paths (issue 15): every case here failed before outdir.py.

The CLI runs in a child with a file-size limit, so that a regression of the
`build -o /` guard ends in SIGXFSZ instead of copying /dev/zero until the disk
is full (what the old staging step did).
"""

from __future__ import annotations

import errno
import os
import re
import resource
import signal
import socket
import stat
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

import armcli.io.files as fsio
import armcli.io.together as together
from armcli.errors import BuildError, OutputRefusedError
from armcli.io.files import write_tree_atomic
from armcli.io.outdir import MARKER_NAME
from tests import helpers

FILE_LIMIT_BYTES = 50_000_000  # far above any armcli output, far below a full disk
TRAJECTORY = (
    "{joint_names: [arm_base_forearm_joint], points: [{positions: [0.2], time_from_start: 0.5}]}"
)


def _limit_files() -> None:
    resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_LIMIT_BYTES, FILE_LIMIT_BYTES))


def run_cli(
    args: list[str], cwd: Path, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    """The shared runner, with a cap on the size of any file the command writes."""
    return helpers.run_cli(args, cwd, env, preexec_fn=_limit_files)


def _stages(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if "armcli-stage" in p.name)


def _fail(proc: subprocess.CompletedProcess[str], pattern: str) -> None:
    assert proc.returncode == 2, (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr and "internal error" not in proc.stderr
    first = proc.stderr.strip().splitlines()[0]
    assert re.search(pattern, first), first


@pytest.mark.parametrize("command", ["build", "ros-package"])
def test_filesystem_root_refused(command: str, root: Path, default_spec_path: Path) -> None:
    before = sorted(os.listdir("/"))
    proc = run_cli([command, str(default_spec_path), "-o", "/"], root)
    _fail(proc, r"error: / --out: is a filesystem root or mount point")
    assert sorted(os.listdir("/")) == before


def test_home_refused(tmp_path: Path, root: Path, default_spec_path: Path) -> None:
    home = tmp_path / "home"
    home.mkdir()
    proc = run_cli(["build", str(default_spec_path), "-o", str(home)], root, {"HOME": str(home)})
    _fail(proc, r"home --out: is the home directory")
    assert list(home.iterdir()) == []


def test_foreign_nonempty_dir_needs_force(
    tmp_path: Path, root: Path, default_spec_path: Path
) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("my notes")
    proc = run_cli(["build", str(default_spec_path), "-o", str(out)], root)
    _fail(proc, r"mine --out: exists, is not empty and was not written by armcli")
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
    forced = run_cli(["build", str(default_spec_path), "-o", str(out), "--force"], root)
    assert forced.returncode == 0, forced.stderr
    assert (out / "notes.txt").read_text() == "my notes"
    assert (out / MARKER_NAME).is_file()
    again = run_cli(["build", str(default_spec_path), "-o", str(out)], root)  # marked now
    assert again.returncode == 0, again.stderr


def _special(kind: str, path: Path) -> None:
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "socket":
        with socket.socket(socket.AF_UNIX) as s:
            s.bind(str(path))
    else:
        if os.geteuid() != 0:
            pytest.skip("creating a device node needs root")
        os.mknod(path, 0o600 | stat.S_IFCHR, os.makedev(1, 5))  # 1,5 is /dev/zero


@pytest.fixture
def small_files() -> Iterator[None]:
    """Files over FILE_LIMIT_BYTES fail with EFBIG in this process (a copy of /dev/zero)."""
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    old = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_LIMIT_BYTES, hard))
    yield
    resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
    signal.signal(signal.SIGXFSZ, old)


@pytest.mark.parametrize(
    ("kind", "word"), [("fifo", "FIFO"), ("socket", "socket"), ("device", "device")]
)
def test_special_files_never_opened(
    kind: str, word: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, small_files: None
) -> None:
    out = tmp_path / "o"
    write_tree_atomic(out, {"a.txt": b"1"})
    _special(kind, out / "special")
    inode = (out / "special").lstat().st_ino
    write_tree_atomic(out, {"a.txt": b"2"})  # same filesystem: carried over as a hard link
    assert (out / "special").lstat().st_ino == inode

    def cross_device(*args: object, **kwargs: object) -> None:
        raise OSError(errno.EXDEV, os.strerror(errno.EXDEV))

    monkeypatch.setattr(os, "link", cross_device)  # as for `-o /`: /dev is another filesystem
    with pytest.raises(OutputRefusedError, match=rf"special: is a {word} that cannot be hard"):
        write_tree_atomic(out, {"a.txt": b"3"})
    assert (out / "a.txt").read_bytes() == b"2"
    assert _stages(tmp_path) == []
    (out / "special").unlink()
    write_tree_atomic(out, {"a.txt": b"3"})  # regular files are copied when links fail
    assert (out / "a.txt").read_bytes() == b"3"


def test_no_write_through_symlink_inside_output(tmp_path: Path) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    out = tmp_path / "o"
    write_tree_atomic(out, {"a.txt": b"a"})
    (out / "config").symlink_to(outside)
    with pytest.raises(
        OutputRefusedError, match=r"config/x\.yaml: a directory on the way is a symlink"
    ):
        write_tree_atomic(out, {"a.txt": b"a", "config/x.yaml": b"evil"})
    assert list(outside.iterdir()) == []
    assert (out / "config").is_symlink() and _stages(tmp_path) == []


def test_symlinked_output_dir_updated_through_link(
    tmp_path: Path, root: Path, default_spec_path: Path
) -> None:
    real = tmp_path / "real"
    assert run_cli(["build", str(default_spec_path), "-o", str(real)], root).returncode == 0
    fresh = (real / "my_robot.urdf").read_bytes()
    (real / "my_robot.urdf").write_text("stale")
    link = tmp_path / "link"
    link.symlink_to(real)
    proc = run_cli(["build", str(default_spec_path), "-o", str(link)], root)
    assert proc.returncode == 0, proc.stderr
    assert link.is_symlink() and link.resolve() == real.resolve()
    assert (real / "my_robot.urdf").read_bytes() == fresh
    assert _stages(tmp_path) == []


def test_permissions_of_existing_dirs_kept(tmp_path: Path) -> None:
    out = tmp_path / "o"
    write_tree_atomic(out, {"a.txt": b"1", "sub/b.txt": b"1"})
    os.chmod(out / "sub", 0o750)
    os.chmod(out, 0o555)
    write_tree_atomic(out, {"a.txt": b"2", "sub/b.txt": b"2"})
    assert stat.S_IMODE(out.stat().st_mode) == 0o555
    assert stat.S_IMODE((out / "sub").stat().st_mode) == 0o750
    assert (out / "sub" / "b.txt").read_bytes() == b"2"
    assert _stages(tmp_path) == []
    os.chmod(out, 0o755)


def test_stale_stage_entries_of_any_type_removed(tmp_path: Path) -> None:
    out = tmp_path / "o"
    write_tree_atomic(out, {"a.txt": b"1"})
    keep = tmp_path / "keep"
    keep.mkdir()
    (keep / "precious").write_text("x")
    dead = 999_999_990  # above any pid_max: no such process
    (tmp_path / f".o.armcli-stage-{dead}-file").write_text("left by kill -9")
    (tmp_path / f".o.armcli-stage-{dead + 1}-link").symlink_to(keep)
    (tmp_path / f".o.armcli-stage-{dead + 2}-dir" / "x").mkdir(parents=True)
    os.chmod(tmp_path / f".o.armcli-stage-{dead + 2}-dir", 0o555)
    write_tree_atomic(out, {"a.txt": b"2"})
    assert _stages(tmp_path) == []
    assert (keep / "precious").read_text() == "x"  # a link is removed, never followed


@pytest.mark.skipif(os.geteuid() != 0, reason="needs root to give a directory to another user")
def test_another_users_stage_entries_are_left_alone(tmp_path: Path) -> None:
    """Issue 42: a stale-looking stage of another user is theirs, never removed (was rmtree'd)."""
    out = tmp_path / "o"
    theirs = tmp_path / f".o.armcli-stage-{999_999_990}-dir"
    (theirs / "notes").mkdir(parents=True)
    for p in (theirs, theirs / "notes"):
        os.chown(p, 65534, 65534)
    write_tree_atomic(out, {"a.txt": b"1"})
    assert (theirs / "notes").is_dir()


def test_out_of_space_error_has_no_none(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def full(*args: object) -> Path:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(fsio, "stage_file", full)
    with pytest.raises(BuildError) as info:
        write_tree_atomic(tmp_path / "o", {"a.txt": b"1"})
    assert str(info.value).endswith("cannot write: No space left on device"), str(info.value)
    monkeypatch.setattr(together, "stage_file", full)  # single files: the one staging writer
    with pytest.raises(BuildError) as single:
        fsio.write_file_atomic(tmp_path / "f.txt", b"1")
    assert str(single.value).endswith("cannot write: No space left on device"), str(single.value)


def test_simulate_validates_every_output_first(
    tmp_path: Path, root: Path, default_spec_path: Path
) -> None:
    (tmp_path / "plots").mkdir()
    args = ["simulate", str(default_spec_path), "-m", TRAJECTORY, "--duration", "0.5"]
    proc = run_cli(
        [*args, "--output", str(tmp_path / "s.csv"), "--plot", str(tmp_path / "plots")], root
    )
    _fail(proc, r"plots --plot: is a directory, expected a file path")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plots"]


@pytest.mark.parametrize(
    "args",
    [
        ["export", "mjcf", "{spec}", "-o", "{dir}"],
        ["tune", "{spec}", "--output", "{tmp}/t.json", "--plot", "{dir}"],
        ["render", "{spec}", "-o", "{dir}"],
        ["tree", "{spec}", "-o", "{dir}"],
    ],
    ids=["export", "tune", "render", "tree"],
)
def test_output_file_paths_checked_first(
    args: list[str], tmp_path: Path, root: Path, default_spec_path: Path
) -> None:
    (tmp_path / "plots").mkdir()
    where = {"spec": str(default_spec_path), "dir": str(tmp_path / "plots"), "tmp": str(tmp_path)}
    proc = run_cli([a.format(**where) for a in args], root)
    _fail(proc, r"plots --(out|plot): is a directory, expected a file path")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plots"]
