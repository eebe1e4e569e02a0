"""`view --replay run.mcap` reads a hostile file as safely as a CSV (issue 20).

The MCAP reader opened any path (a FIFO blocked it forever), read files of any size,
and took NaN joint positions into the replay.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from armcli.errors import InputError
from armcli.sim import rosbag
from tests.helpers import ROOT

JOINT = "arm_base_forearm_joint"
FAST_S = 30.0  # a refusal is immediate; a blocked open() never returns


def _mcap(path: Path, positions: list[float]) -> Path:
    from mcap_ros2.writer import Writer

    with path.open("wb") as fh:
        writer = Writer(fh)
        schema = writer.register_msgdef(
            rosbag.JOINT_STATE, rosbag.message_definition(rosbag.JOINT_STATE)
        )
        for k, q in enumerate(positions):
            ns = k * 100_000_000
            msg = {
                "header": {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": ""},
                "name": [JOINT],
                "position": [q],
                "velocity": [],
                "effort": [],
            }
            writer.write_message(rosbag.JOINT_STATES, schema, msg, log_time=ns, publish_time=ns)
        writer.finish()
    return path


def test_a_valid_file_still_replays(tmp_path: Path) -> None:
    run = rosbag.load_replay(_mcap(tmp_path / "ok.mcap", [0.0, 0.5, 1.0]), [JOINT])
    assert run.duration == pytest.approx(0.2)  # three states 0.1 s apart


def test_non_finite_position_is_refused(tmp_path: Path) -> None:
    path = _mcap(tmp_path / "nan.mcap", [0.0, math.nan, 1.0])
    with pytest.raises(InputError, match=rf"nan\.mcap: /joint_states at t = 0\.1 s: {JOINT}"):
        rosbag.load_replay(path, [JOINT])  # before: a NaN pose in the viewer


def test_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "run.mcap"
    os.mkfifo(fifo)
    code = (
        "from armcli.errors import InputError\nfrom armcli.sim import rosbag\n"
        f"try:\n    rosbag.load_replay({str(fifo)!r}, ['j'])\n"
        "except InputError as e:\n    print(e)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=FAST_S
    )  # before: TimeoutExpired, open() waited for a writer
    assert "is a FIFO" in proc.stdout, proc.stderr


def test_size_is_capped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = _mcap(tmp_path / "big.mcap", [0.0, 0.5])
    monkeypatch.setattr(rosbag, "MAX_REPLAY_BYTES", path.stat().st_size - 1)
    with pytest.raises(InputError, match="larger than the"):
        rosbag.load_replay(path, [JOINT])
