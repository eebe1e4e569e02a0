"""Atomic outputs: killed builds leave the previous files byte-identical."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import armcli.io.files as fsio
from armcli.errors import BuildError, OutputRefusedError
from armcli.io.files import write_file_atomic, write_tree_atomic
from armcli.io.outdir import MARKER_NAME, MARKER_TEXT
from tests.helpers import run_cli

KILL_WAIT_S = 60.0  # bound on how long the child may take to reach the injected pause

# The child runs the real CLI with one function replaced by "announce, then hang",
# so the test can SIGKILL it at a known point of the build.
_CHILD = """
import sys, time
from pathlib import Path
import armcli.{module} as target
marker = Path(sys.argv[1])
real = target.{func}
def hang(*args, **kwargs):
    marker.write_text("paused")
    time.sleep(600)
    return real(*args, **kwargs)
target.{func} = hang
from armcli.cli import main
sys.argv = ["armcli", *sys.argv[2:]]
main()
"""


def _snapshot(d: Path) -> dict[str, bytes]:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


@pytest.mark.parametrize(
    ("module", "func"),
    [("compiler.expand", "expand"), ("io.files", "_exchange"), ("io.files", "stage_file")],
    ids=["during-xacro", "before-swap", "while-staging"],
)
def test_sigkill_mid_build_keeps_previous_outputs(
    tmp_path: Path, default_spec_path: Path, module: str, func: str
) -> None:
    out = tmp_path / "urdf"
    write_tree_atomic(out, {"old.txt": b"previous build\n", "arm.xacro": b"<robot/>\n"})
    (out / "meshes").mkdir()
    (out / "meshes" / "user.stl").write_bytes(b"solid user")
    before = _snapshot(out)
    marker = tmp_path / "paused"
    script = _CHILD.format(module=module, func=func)
    child = subprocess.Popen(
        [
            sys.executable,
            "-c",
            script,
            str(marker),
            "build",
            str(default_spec_path),
            "-o",
            str(out),
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + KILL_WAIT_S
        while not marker.exists() and child.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert marker.exists(), "child never reached the injected pause"
        os.kill(child.pid, signal.SIGKILL)
        child.wait(timeout=10)
    finally:
        if child.poll() is None:
            child.kill()
    assert _snapshot(out) == before
    # The next build replaces everything in one swap, keeps the user's file, and
    # removes the dead process's staging directory.
    fsio_build = run_cli(["build", default_spec_path, "-o", out])
    assert fsio_build.returncode == 0, fsio_build.stderr
    assert (out / "meshes" / "user.stl").read_bytes() == b"solid user"
    assert (out / "my_robot.urdf").is_file()
    assert [p.name for p in tmp_path.iterdir() if "armcli-stage" in p.name] == []


def test_unchanged_rebuild_touches_nothing(tmp_path: Path) -> None:
    files = {"a.txt": b"a", "sub/b.txt": b"b"}
    write_tree_atomic(tmp_path / "o", files)
    inode = (tmp_path / "o" / "a.txt").stat().st_ino
    write_tree_atomic(tmp_path / "o", files)
    assert (tmp_path / "o" / "a.txt").stat().st_ino == inode


def test_fallback_without_exchange(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    write_tree_atomic(tmp_path / "o", {"a.txt": b"1", "keep.txt": b"k"})
    monkeypatch.setattr(fsio, "_exchange", lambda a, b: False)
    write_tree_atomic(tmp_path / "o", {"a.txt": b"2"})
    assert _snapshot(tmp_path / "o") == {"a.txt": b"2", "keep.txt": b"k", MARKER_NAME: MARKER_TEXT}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o"]


def test_refuses_escaping_names_and_directories(tmp_path: Path) -> None:
    for bad in ("../evil.txt", "/etc/passwd", "a/../../b", ""):
        with pytest.raises(OutputRefusedError, match="outside the output directory"):
            write_tree_atomic(tmp_path / "o", {bad: b"x"})
    write_tree_atomic(tmp_path / "o", {"f.txt": b"old"})
    (tmp_path / "o" / "dir").mkdir()
    with pytest.raises(BuildError, match="is a directory"):
        write_tree_atomic(tmp_path / "o", {"dir": b"x", "f.txt": b"new"})
    assert (tmp_path / "o" / "f.txt").read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o"]


def test_single_file(tmp_path: Path) -> None:
    target = tmp_path / "deep" / "x.csv"
    write_file_atomic(target, "a,b\n")
    assert target.read_text() == "a,b\n"
    assert oct(target.stat().st_mode & 0o777) == oct(0o666 & ~_current_umask())
    with pytest.raises(BuildError, match="is a directory"):
        write_file_atomic(tmp_path / "deep", b"x")


def _current_umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
