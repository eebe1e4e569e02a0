"""A robot that tips is flagged by `simulate` and by `check --trajectory`; the seed is not.

The variant is the seed spec with one line more: the diff-drive plugin's
max_wheel_acceleration at 5 m/s² instead of its default 1 (gazebo_ros_diff_drive ramps the
wheels' rim speed by at most that much per second, so it is the base's acceleration and
braking). Along the fast swing (tests/fixtures/tipover/swing.yaml) the arm's reaction
alone leaves 73.7 mm of margin, but with the base accelerating at 5 m/s² the zero-moment
point leaves the polygon toward the rear: the largest acceleration that holds along the
swing is 3.46 m/s² (tests/sim/test_zmp.py checks the point itself against closed forms
and MuJoCo). These runs check that the two commands see it and say so.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from tests.helpers import DEFAULT_SPEC, FIXTURES, run_main

SWING = FIXTURES / "tipover" / "swing.yaml"
TIPPING_ACCEL = 5.0  # [m/s²] > 3.46 m/s², the largest that holds along the swing
SEED_ACCEL = 1.0  # [m/s²] the spec's default max_wheel_acceleration


def braking_spec(tmp_path: Path) -> Path:
    """The seed spec with a diff drive that accelerates and brakes at TIPPING_ACCEL."""
    text = DEFAULT_SPEC.read_text()
    line = "    wheel_diameter: 0.2\n"
    assert text.count(line) == 1
    path = tmp_path / "braking.yaml"
    path.write_text(text.replace(line, f"{line}    max_wheel_acceleration: {TIPPING_ACCEL}\n"))
    return path


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    return run_main(args, capsys)


def test_simulate_flags_the_variant_and_passes_the_seed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    csv_path = tmp_path / "seed.csv"
    code, out, err = run(["simulate", DEFAULT_SPEC, "-t", SWING, "-o", csv_path], capsys)
    assert code == 0, err
    assert f"base accel {SEED_ACCEL:g} m/s²" in out and "TIPS" not in out
    with csv_path.open() as fh:
        rows = list(csv.DictReader(fh))
    assert min(float(r["zmp.margin_base"]) for r in rows) > 0.02  # 52 mm at its worst

    csv_path = tmp_path / "variant.csv"
    code, out, err = run(["simulate", braking_spec(tmp_path), "-t", SWING, "-o", csv_path], capsys)
    assert code == 1
    assert "the robot tips over" in err and "toward rear" in err
    assert f"base accel {TIPPING_ACCEL:g} m/s²" in out and "TIPS" in out
    with csv_path.open() as fh:  # the files are written before the error
        rows = list(csv.DictReader(fh))
    assert min(float(r["zmp.margin_base"]) for r in rows) < 0
    assert min(float(r["zmp.margin"]) for r in rows) > 0  # the arm alone does not tip it


def test_check_trajectory_flags_the_variant_and_passes_the_seed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["--trajectory", SWING, "--format", "json"]
    code, out, err = run(["check", DEFAULT_SPEC, *args], capsys)
    assert code == 0, err
    robot = json.loads(out)["files"][0]
    assert robot["findings"] == []
    zmp = robot["summary"]["zmp"]
    assert zmp["base_accel"] == SEED_ACCEL and zmp["min_margin"] > 0.02

    code, out, _ = run(["check", braking_spec(tmp_path), *args], capsys)
    assert code == 1
    robot = json.loads(out)["files"][0]
    (f,) = robot["findings"]
    assert f["rule"] == "zmp-outside-support" and f["severity"] == "error"
    assert f["values"]["margin"] < 0 and f["values"]["direction"] == "rear"
    assert f["spec"]["field"] == "mobile_base.diff_drive.max_wheel_acceleration"  # the line added
    holds = f["fix"]["max_wheel_acceleration"]
    assert SEED_ACCEL < holds < TIPPING_ACCEL  # the fix: an acceleration that holds
    assert robot["summary"]["zmp"]["max_base_accel"] >= holds
