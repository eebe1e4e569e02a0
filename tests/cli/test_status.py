"""The one-line status a silent command prints at a terminal (commands.status, issue 31)."""

from __future__ import annotations

import io
import time

from armcli.commands.status import Status, start_status

QUICK_S = 0.05  # [s] a status delay short enough for a test
WAIT_S = 0.5  # [s] far beyond it: the timer thread has run


def test_a_silent_command_gets_one_status_line() -> None:
    err = io.StringIO()
    status = Status("check", err, after=QUICK_S)
    status.start()
    time.sleep(WAIT_S)
    status.stop()
    assert err.getvalue().count("\n") == 1 and err.getvalue().startswith("armcli check: working")


def test_output_before_the_delay_cancels_it() -> None:
    err, out = io.StringIO(), io.StringIO()
    status = Status("check", err, after=QUICK_S)
    watched = status.watch(out)
    status.start()
    watched.write("robot 'my_robot': ...\n")
    time.sleep(WAIT_S)
    assert err.getvalue() == "" and out.getvalue() == "robot 'my_robot': ...\n"


def test_no_status_into_a_pipe_or_for_help() -> None:
    # pytest's captured stderr is no terminal: logs and tests see only the command's output
    assert start_status(["check", "robot.urdf"]) is None
    assert start_status(["check", "--help"]) is None
