"""Several files replaced together (armcli.io.together): all new or all old, never a mix.

Issue 20: `simulate --output X --plot Y` wrote the CSV, then drew the plot: 17 of 60
runs killed at random left a new CSV beside an old plot. `tune --write` made a 0600
spec 0644 and replaced a symlinked spec with a plain file. Each test kills or breaks a
write at one chosen point (a child process SIGKILLs itself there) and checks the files.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from armcli.errors import ArmcliWarning, OutputRefusedError
from armcli.io.files import write_file_atomic
from armcli.io.together import TAG, finish_interrupted, write_files_together
from tests.helpers import ROOT

CHILD_TIMEOUT_S = 60


def _child(script: str) -> subprocess.CompletedProcess[str]:
    """Run `script` in a fresh interpreter (it may SIGKILL itself)."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(script)],
        capture_output=True,
        text=True,
        timeout=CHILD_TIMEOUT_S,
        check=False,
        cwd=ROOT,
    )


def _pair(tmp_path: Path) -> tuple[Path, Path]:
    (tmp_path / "plots").mkdir()
    a, b = tmp_path / "states.csv", tmp_path / "plots" / "tracking.png"
    a.write_bytes(b"old-a")
    b.write_bytes(b"old-b")
    return a, b


def _leftovers(*dirs: Path) -> list[str]:
    return sorted(p.name for d in dirs for p in d.iterdir() if TAG in p.name)


def test_both_files_change(tmp_path: Path) -> None:
    a, b = _pair(tmp_path)
    assert write_files_together({a: b"new-a", b: b"new-b"}) == [a, b]
    assert (a.read_bytes(), b.read_bytes()) == (b"new-a", b"new-b")
    assert _leftovers(a.parent, b.parent) == []


def test_killed_while_staging_changes_nothing(tmp_path: Path) -> None:
    a, b = _pair(tmp_path)
    proc = _child(
        f"""
        import os, signal
        from pathlib import Path
        from armcli.io import together
        real, calls = os.fsync, []
        def fsync(fd):
            real(fd)
            calls.append(fd)
            if len(calls) == 2:  # the second file is staged, nothing renamed yet
                os.kill(os.getpid(), signal.SIGKILL)
        os.fsync = fsync
        together.write_files_together({{Path({str(a)!r}): b"new-a", Path({str(b)!r}): b"new-b"}})
        """
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    assert (a.read_bytes(), b.read_bytes()) == (b"old-a", b"old-b")
    assert _leftovers(a.parent, b.parent)  # the staged files of the killed run
    write_files_together({tmp_path / "other.txt": b"x"})  # the next write into the directory
    finish_interrupted(b.parent)
    assert _leftovers(a.parent, b.parent) == []
    assert (a.read_bytes(), b.read_bytes()) == (b"old-a", b"old-b")


def test_killed_between_renames_is_completed_by_the_next_write(tmp_path: Path) -> None:
    a, b = _pair(tmp_path)
    proc = _child(
        f"""
        import os, signal
        from pathlib import Path
        from armcli.io import together
        real = os.replace
        def replace(src, dst):
            real(src, dst)
            if str(dst) == {str(a)!r}:  # the first target renamed, the second not yet
                os.kill(os.getpid(), signal.SIGKILL)
        os.replace = replace
        together.write_files_together({{Path({str(a)!r}): b"new-a", Path({str(b)!r}): b"new-b"}})
        """
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    assert (a.read_bytes(), b.read_bytes()) == (b"new-a", b"old-b")  # the microsecond window
    with pytest.warns(ArmcliWarning, match="completed .*tracking.png"):  # said on stderr
        write_files_together({b.parent / "unrelated.txt": b"x"})  # the next write into b's dir
    assert (a.read_bytes(), b.read_bytes()) == (b"new-a", b"new-b")
    assert len(_leftovers(a.parent)) == 1  # a's journal: each directory completes its own files
    write_files_together({a.parent / "unrelated.txt": b"x"})  # nothing left to do: no warning
    assert _leftovers(a.parent, b.parent) == []


def test_termination_signals_wait_for_the_set(tmp_path: Path) -> None:
    a, b = _pair(tmp_path)
    proc = _child(
        f"""
        import os, signal
        from pathlib import Path
        from armcli.io import together
        real = os.replace
        def replace(src, dst):
            if str(dst) == {str(a)!r}:
                os.kill(os.getpid(), signal.SIGTERM)  # held until both are renamed
            real(src, dst)
        os.replace = replace
        together.write_files_together({{Path({str(a)!r}): b"new-a", Path({str(b)!r}): b"new-b"}})
        """
    )
    assert proc.returncode == -signal.SIGTERM, proc.stderr
    assert (a.read_bytes(), b.read_bytes()) == (b"new-a", b"new-b")
    assert _leftovers(a.parent, b.parent) == []


def test_symlink_is_written_through_and_mode_kept(tmp_path: Path) -> None:
    real = tmp_path / "real" / "robot.yaml"
    real.parent.mkdir()
    real.write_text("old\n")
    real.chmod(0o600)
    link = tmp_path / "robot.yaml"
    link.symlink_to(real)
    write_file_atomic(link, "new\n")
    assert link.is_symlink() and real.read_text() == "new\n"  # before: link replaced by a file
    assert real.stat().st_mode & 0o777 == 0o600  # before: 0644 from the umask


def test_missing_directory_is_refused_without_creating_it(tmp_path: Path) -> None:
    missing = tmp_path / "nonexistent" / "dir" / "x.png"
    with pytest.raises(OutputRefusedError, match="does not exist"):
        write_files_together({tmp_path / "a.csv": b"a", missing: b"b"})
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_same_target_twice_is_refused(tmp_path: Path) -> None:
    (tmp_path / "a").write_bytes(b"old")
    os.symlink(tmp_path / "a", tmp_path / "b")
    with pytest.raises(OutputRefusedError, match="named twice"):
        write_files_together({tmp_path / "a": b"1", tmp_path / "b": b"2"})
    assert (tmp_path / "a").read_bytes() == b"old"
