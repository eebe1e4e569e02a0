"""`armcli tune` end to end through the real command: outputs, --write, bad input."""

from __future__ import annotations

import json
import shutil
import socket
import stat
import sys
import time
from pathlib import Path

import pytest

from armcli.spec.load import load_spec
from tests.helpers import ROOT, run_main

SPEC = ROOT / "specs" / "my_robot.yaml"
PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
QUICK = ["--trials", "4", "--batch", "2", "--settle", "0.5", "--trajectory", str(PICK)]
UNREACHABLE_S = 10.0  # [s] an unreachable scheduler must be reported well within this
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    return run_main(["tune", *args], capsys)


@pytest.fixture
def spec_copy(tmp_path: Path) -> Path:
    """The seed spec with its trajectories, in a scratch directory."""
    shutil.copytree(SPEC.parent / "trajectories", tmp_path / "trajectories")
    path = tmp_path / "robot.yaml"
    shutil.copy(SPEC, path)
    return path


def test_outputs_and_write(spec_copy: Path, tmp_path: Path,
                           capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    out_json, out_png = tmp_path / "tune.json", tmp_path / "tune.png"
    code, out, err = run([str(spec_copy), *QUICK, "-o", str(out_json), "--plot", str(out_png),
                          "--write"], capsys)  # fmt: skip
    assert code == 0, err
    assert "binding" in out and "mean RMS error: spec" in out
    doc = json.loads(out_json.read_text(encoding="utf-8"))
    assert doc["schema_version"] == 1
    assert set(doc["results"]) == {"spec", "start", "tuned"}
    assert len(doc["history"]) == 4
    best = doc["best"]
    gains = load_spec(spec_copy).control.gains
    # --write stores the reported (rounded) best gains.
    assert [gains[j].kp for j in doc["problem"]["joints"]] == best["kp"]
    assert [gains[j].kd for j in doc["problem"]["joints"]] == best["kd"]
    assert out_png.read_bytes().startswith(PNG_MAGIC)
    documented = (ROOT / "docs" / "tune.md").read_text(encoding="utf-8")
    joint_doc = doc["results"]["tuned"]["joints"][doc["problem"]["joints"][0]]
    keys = [*doc, *doc["problem"], *doc["search"], *doc["search"]["weights"], *doc["start"][0],
            *doc["results"]["tuned"], *joint_doc, *doc["best"], *doc["history"][0]]  # fmt: skip
    assert [k for k in keys if k not in documented] == []  # docs/tune.md lists every key


@pytest.mark.parametrize(
    "args, message",
    [
        (["--trials", "0"], "--trials: must be >= 1"),
        (["--joints", "elbow"], "unknown joint 'elbow'"),
        (["--zeta", "0"], "--zeta: must be > 0"),
        (["--mass-scale", "1.2,0.8"], "--mass-scale: need 0 < a <= b"),
        (["--output", "x.csv"], "must end in .json"),
        (["--scheduler", "nonsense://x"], "not a Dask address"),
        (
            ["--trajectory", str(ROOT / "tests" / "fixtures" / "tune" / "unknown_joint.yaml")],
            "unknown joint 'wrist_joint'",
        ),
    ],
)
def test_bad_options(args: list[str], message: str, spec_copy: Path,
                     capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    code, _, err = run([str(spec_copy), *QUICK, *args], capsys)
    assert code == 2
    assert message in err
    assert err.count("\n") == 1  # one line


def test_unknown_loop_lists_the_choices(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(["--loop", "magic"], capsys)
    assert code == 2  # click's usage error
    assert "unknown value 'magic'; valid: implicit, explicit" in err


def test_trajectory_outside_limits(spec_copy: Path, tmp_path: Path,
                                   capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    bad = tmp_path / "bad.yaml"
    bad.write_text("joint_names: [arm_base_forearm_joint]\n"
                   "points: [{positions: [2.5], time_from_start: 1.0}]\n")  # fmt: skip
    code, _, err = run([str(spec_copy), "--trajectory", str(bad)], capsys)
    assert code == 2
    assert str(bad) in err and "outside" in err


def test_scheduler_without_dask_says_what_to_install(
    spec_copy: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    code, _, err = run([str(spec_copy), *QUICK, "--scheduler", "tcp://127.0.0.1:8786"], capsys)
    assert code == 2
    assert "pip install 'dask[distributed]'" in err


def test_shared_trajectory_folder_other_spec(capsys: pytest.CaptureFixture[str],
                                             tmp_path: Path) -> None:  # fmt: skip
    # specs/trajectories/ holds my_robot's examples: the tabletop arm falls back to its poses.
    out_json = tmp_path / "t.json"
    spec = ROOT / "specs" / "tabletop_arm.yaml"
    code, _, err = run([str(spec), "--trials", "2", "--settle", "0.3", "-o", str(out_json)], capsys)
    assert code == 0, err
    labels = [c["label"] for c in json.loads(out_json.read_text())["problem"]["cases"]]
    assert labels and all(label.startswith("pose ") for label in labels)


def test_unreachable_scheduler_fails_fast(spec_copy: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    # A port that accepts TCP but never answers: the Dask client alone would wait forever.
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(1)
        port = silent.getsockname()[1]
        t0 = time.monotonic()
        code, _, err = run([str(spec_copy), *QUICK, "--scheduler", f"tcp://127.0.0.1:{port}"],
                           capsys)  # fmt: skip
        elapsed = time.monotonic() - t0
    assert code == 2
    assert "cannot reach the Dask scheduler" in err
    assert elapsed < UNREACHABLE_S


def test_read_only_spec_with_write(spec_copy: Path, capsys: pytest.CaptureFixture[str]) -> None:
    before = spec_copy.read_bytes()
    spec_copy.chmod(stat.S_IRUSR | stat.S_IRGRP)
    code, out, err = run([str(spec_copy), *QUICK, "--write"], capsys)
    assert code == 2
    assert "read-only" in err and str(spec_copy) in err
    assert out == ""  # refused before any tuning
    assert spec_copy.read_bytes() == before


def test_named_poses_as_steps_without_trajectories(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "robot.yaml"  # no trajectories/ next to it
    shutil.copy(SPEC, path)
    out_json = tmp_path / "t.json"
    code, _, err = run([str(path), "--trials", "2", "--settle", "0.5", "-o", str(out_json)],
                       capsys)  # fmt: skip
    assert code == 0, err
    labels = [c["label"] for c in json.loads(out_json.read_text())["problem"]["cases"]]
    assert labels == ["pose folded", "pose reach"]  # home is the start: no step
