"""create_files: all or nothing, never replacing, nothing staged left behind."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from armcli.errors import ExistingFileError, OutputRefusedError
from armcli.io import newfiles
from armcli.io.files import write_tree_atomic
from armcli.io.newfiles import create_files

FILES = {"a.yaml": b"a\n", "sub/dir/b.yaml": b"b\n", "c.md": b"c\n"}


def _tree(root: Path) -> list[str]:
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*"))


def test_into_an_existing_directory_keeps_other_files(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "mine.txt").write_text("x")
    written = create_files(tmp_path, FILES)
    assert written == [tmp_path / r for r in FILES]
    assert _tree(tmp_path) == [
        "a.yaml", "c.md", "sub", "sub/dir", "sub/dir/b.yaml", "sub/mine.txt",
    ]  # fmt: skip
    assert all((tmp_path / r).read_bytes() == data for r, data in FILES.items())


def test_a_failure_midway_undoes_everything(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "keep.txt").write_text("x")
    calls = []
    real = newfiles._place

    def fail_third(src: Path, dst: Path) -> None:
        calls.append(dst)
        if len(calls) == 3:
            raise FileExistsError(17, "File exists", str(dst))  # a file appeared meanwhile
        real(src, dst)

    monkeypatch.setattr(newfiles, "_place", fail_third)
    with pytest.raises(ExistingFileError, match="appeared while writing"):
        create_files(tmp_path, FILES)
    assert _tree(tmp_path) == ["keep.txt"]  # links and the directories made for them undone


def test_existing_target_refused_before_writing(tmp_path: Path) -> None:
    (tmp_path / "c.md").write_text("mine")
    with pytest.raises(ExistingFileError, match=r"c\.md: already exists"):
        create_files(tmp_path, FILES)
    assert _tree(tmp_path) == ["c.md"]


def test_a_dangling_symlink_counts_as_existing(tmp_path: Path) -> None:
    (tmp_path / "a.yaml").symlink_to(tmp_path / "nowhere")
    with pytest.raises(ExistingFileError):
        create_files(tmp_path, FILES)
    assert not (tmp_path / "nowhere").exists()


def test_a_new_directory_appears_complete(tmp_path: Path) -> None:
    create_files(tmp_path / "p", FILES)
    assert _tree(tmp_path) == ["p", "p/a.yaml", "p/c.md", "p/sub", "p/sub/dir", "p/sub/dir/b.yaml"]


@pytest.mark.parametrize("rel", ["../x", "/abs", "", "a/../../b"])
def test_paths_outside_are_refused(tmp_path: Path, rel: str) -> None:
    # the same rule and error as the atomic tree writer (io.outdir.relative_inside)
    with pytest.raises(OutputRefusedError, match="outside the output directory"):
        create_files(tmp_path, {rel: b""})
    with pytest.raises(OutputRefusedError, match="outside the output directory"):
        write_tree_atomic(tmp_path / "o", {rel: b""})


def test_a_symlinked_subdirectory_is_not_written_through(tmp_path: Path) -> None:
    """Issue 20: `init` wrote trajectories/*.yaml into wherever `trajectories` pointed."""
    project, elsewhere = tmp_path / "project", tmp_path / "elsewhere"
    project.mkdir()
    elsewhere.mkdir()
    (project / "trajectories").symlink_to(elsewhere)
    with pytest.raises(OutputRefusedError, match="symlink"):
        create_files(project, {"armcli.yaml": b"a", "trajectories/pick.yaml": b"b"})
    assert list(elsewhere.iterdir()) == []
    assert sorted(p.name for p in project.iterdir()) == ["trajectories"]


def test_a_killed_runs_stage_is_removed(tmp_path: Path) -> None:
    stale = tmp_path / f".armcli-new-{_dead_pid()}-abc"
    stale.mkdir()
    (stale / "armcli.yaml").write_bytes(b"half")
    create_files(tmp_path, {"armcli.yaml": b"a"})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["armcli.yaml"]


@pytest.mark.skipif(os.geteuid() != 0, reason="needs root to give a directory to another user")
def test_another_users_stage_is_left_alone(tmp_path: Path) -> None:
    """Issue 42: only this user's stages are armcli's to remove (another's was rmtree'd)."""
    theirs = tmp_path / f".armcli-new-{_dead_pid()}-abc"
    theirs.mkdir()
    os.chown(theirs, 65534, 65534)
    create_files(tmp_path, {"armcli.yaml": b"a"})
    assert theirs.is_dir()


def _dead_pid() -> int:
    """The PID of a process that has exited (its stage would be a killed run's)."""
    proc = subprocess.Popen(["true"])
    proc.wait()
    return proc.pid
