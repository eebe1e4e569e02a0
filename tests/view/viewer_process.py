"""`armcli view` as its own process, stopped with Ctrl-C once it printed its URL."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path


def view_then_ctrl_c(args: list[str], cwd: Path) -> tuple[str, int, str, str]:
    """The first stdout line, then after SIGINT: exit code, rest of stdout, stderr."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "armcli.cli", "view", *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        first = proc.stdout.readline() if proc.stdout else ""
        if first:
            proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return first, proc.returncode, out, err
