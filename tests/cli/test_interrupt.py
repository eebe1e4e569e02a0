"""Ctrl-C in a long command: one line on stderr, exit 130, and no output file at all."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import IO

import pytest

from armcli.cli import INTERRUPTED
from tests.helpers import DEFAULT_SPEC, ROOT

PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
START_TIMEOUT_S = 120.0  # a loaded CI machine imports slowly
STOP_TIMEOUT_S = 60.0


def _wait_for(stream: IO[str], marker: str) -> str:
    seen = ""
    deadline = time.monotonic() + START_TIMEOUT_S
    while marker not in seen:
        line = stream.readline()
        if not line or time.monotonic() > deadline:
            raise AssertionError(f"never saw {marker!r}; got {seen!r}")
        seen += line
    return seen


def _as_at_a_terminal() -> None:
    """Ctrl-C's default disposition in the child, as a terminal's shell gives it.

    A runner started as a background job of a non-interactive shell ignores SIGINT, and an
    ignored signal stays ignored across exec: armcli would never see the Ctrl-C under test.
    """
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _interrupt(args: list[str], marker: str, on_stderr: bool, cwd: Path) -> tuple[int, str]:
    proc = subprocess.Popen(
        [sys.executable, "-m", "armcli", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=cwd,
        preexec_fn=_as_at_a_terminal,
    )
    assert proc.stdout is not None and proc.stderr is not None
    try:
        _wait_for(proc.stderr if on_stderr else proc.stdout, marker)
        time.sleep(0.5)  # well inside the long part
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=STOP_TIMEOUT_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()  # reaped and its pipes closed: nothing left for the next test
    return proc.returncode, err


def test_ctrl_c_in_tune(tmp_path: Path) -> None:
    args = ["tune", str(DEFAULT_SPEC), "-t", str(PICK), "--trials", "100000", "-j", "1",
            "-o", "tune.json", "--plot", "tune.png"]  # fmt: skip
    code, err = _interrupt(args, "model-based start", on_stderr=False, cwd=tmp_path)
    assert code == 130
    assert err.strip().splitlines()[-1] == INTERRUPTED.strip()
    assert err.count("interrupted") == 1 and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []  # no output, no temporary file


@pytest.mark.parametrize("output", ["states.csv", "run.mcap"])
def test_ctrl_c_in_simulate(tmp_path: Path, output: str) -> None:
    # the brace form's warning is printed just before the run starts: the marker
    message = "{joint_names: [arm_base_forearm_joint], points: [{positions: {0.5}}]}"
    args = ["simulate", str(DEFAULT_SPEC), "-m", message, "--duration", "1500",
            "-o", output, "--plot", "track.png"]  # fmt: skip
    code, err = _interrupt(args, "is a YAML mapping", on_stderr=True, cwd=tmp_path)
    assert code == 130
    assert err.strip().splitlines()[-1] == INTERRUPTED.strip()
    assert err.count("interrupted") == 1 and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
