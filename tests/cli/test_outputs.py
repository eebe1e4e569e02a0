"""Output files of the commands: all-or-nothing sets, parents that must exist (issue 20)."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
from pathlib import Path

from tests.helpers import ROOT

TRAJECTORY = ROOT / "specs" / "trajectories" / "home.yaml"
CHILD_TIMEOUT_S = 300


def _simulate(*args: str, prelude: str = "") -> subprocess.CompletedProcess[str]:
    script = textwrap.dedent(prelude) + (
        "from armcli.cli import main\n"
        f"main(['simulate', '--trajectory', {str(TRAJECTORY)!r}, *{list(args)!r}])\n"
    )
    return subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=CHILD_TIMEOUT_S,
        check=False,
        cwd=ROOT,
    )


def test_simulate_killed_while_plotting_keeps_the_old_pair(tmp_path: Path) -> None:
    states, plot = tmp_path / "states.csv", tmp_path / "tracking.png"
    states.write_text("old states\n")
    plot.write_bytes(b"old plot")
    kill_in_plot = """
        import os, signal
        import armcli.sim.plot
        def killed(*args, **kwargs):
            os.kill(os.getpid(), signal.SIGKILL)
        armcli.sim.plot.tracking_png = killed
    """
    proc = _simulate("--output", str(states), "--plot", str(plot), prelude=kill_in_plot)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    # before: the new CSV was already written beside the old plot
    assert states.read_text() == "old states\n" and plot.read_bytes() == b"old plot"


def test_simulate_writes_the_pair(tmp_path: Path) -> None:
    states, plot = tmp_path / "states.csv", tmp_path / "tracking.png"
    proc = _simulate("--output", str(states), "--plot", str(plot))
    assert proc.returncode == 0, proc.stderr
    assert states.read_text().startswith("time") and plot.read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["states.csv", "tracking.png"]


def test_plot_in_missing_directory_exits_2_and_creates_nothing(tmp_path: Path) -> None:
    plot = tmp_path / "nonexistent" / "dir" / "x.png"
    proc = _simulate("--output", str(tmp_path / "s.csv"), "--plot", str(plot))
    assert proc.returncode == 2, proc.stderr
    # one error, wrapped at the width the child sees (readline exports COLUMNS=80 under pytest)
    assert proc.stderr.startswith("error: ") and proc.stderr.count("error:") == 1
    assert "does not exist" in " ".join(proc.stderr.split())
    assert list(tmp_path.iterdir()) == []  # before: nonexistent/dir was created
