"""Numeric options and file-derived counts are bounded (issue 15); each case crashed or ran away."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from armcli.errors import InputError
from armcli.sim.states import load_replay
from tests.helpers import run_cli

CSV_FIELD_LIMIT = csv.field_size_limit()  # 131072: the csv module's default
TRAJECTORY = (
    "{joint_names: [arm_base_forearm_joint], points: [{positions: [0.2], time_from_start: 0.5}]}"
)


def test_replay_field_over_csv_limit_is_an_input_error(tmp_path: Path) -> None:
    huge = tmp_path / "huge.csv"
    huge.write_text("time,j.position\n0," + "1" * (CSV_FIELD_LIMIT + 1) + "\n")
    # issue 20: refused by the line's length (2 cells) before the csv module builds the row
    with pytest.raises(InputError, match=r"huge\.csv:2: line of 2 cells longer than 130 char"):
        load_replay(huge, ["j"])


def test_replay_field_through_view(tmp_path: Path, root: Path, default_spec_path: Path) -> None:
    huge = tmp_path / "huge.csv"
    huge.write_text("time,arm_base_forearm_joint.position\n0," + "1" * 200_000 + "\n")
    proc = run_cli(["view", str(default_spec_path), "--replay", str(huge), "--port", "0"], root)
    assert proc.returncode == 2, proc.stderr
    assert "huge.csv:2: line of 2 cells longer than 130 characters" in proc.stderr
    assert "internal error" not in proc.stderr


@pytest.mark.parametrize("rate", ["1e9", "1000.5", "-1", "nan"])
def test_rate_bounded_by_time_step(
    rate: str, tmp_path: Path, root: Path, default_spec_path: Path
) -> None:
    # The default spec's dt is 0.001 s, so 1/dt = 1000 Hz; 1e9 Hz asked for 52 GiB before.
    out = tmp_path / "s.csv"
    args = ["simulate", str(default_spec_path), "-m", TRAJECTORY, "--output", str(out)]
    proc = run_cli([*args, "--rate", rate], root)
    assert proc.returncode == 2, proc.stderr
    assert "--rate: must be in (0, 1/dt = 1000] Hz" in proc.stderr
    assert not out.exists()


def test_rate_equal_to_one_per_step_writes_every_step(
    tmp_path: Path, root: Path, default_spec_path: Path
) -> None:
    out = tmp_path / "s.csv"
    args = ["simulate", str(default_spec_path), "-m", TRAJECTORY, "--duration", "0.1"]
    proc = run_cli([*args, "--rate", "1000", "--output", str(out)], root)
    assert proc.returncode == 0, proc.stderr
    # 0.1 s at dt = 0.001 s: steps 0..100 inclusive, one row each, plus the header.
    assert len(out.read_text().splitlines()) == 101 + 1


@pytest.mark.parametrize(("option", "value"), [("--samples", "1000000001"), ("--samples", "0")])
def test_ros_package_counts_bounded(
    option: str, value: str, tmp_path: Path, root: Path, default_spec_path: Path
) -> None:
    out = tmp_path / "ros"
    proc = run_cli(["ros-package", str(default_spec_path), "-o", str(out), option, value], root)
    assert proc.returncode == 2, proc.stderr
    assert f"Invalid value for '{option}'" in proc.stderr
    assert not out.exists()


@pytest.mark.parametrize("command", ["plan", "tune", "ros-package"])
@pytest.mark.parametrize("seed", ["-1", str(2**32), str(2**64)])
def test_seed_refused_where_it_is_parsed(
    command: str, seed: str, tmp_path: Path, default_spec_path: Path
) -> None:
    """Issue 42: `--seed -1` or `2**64` was an internal error (tune), click's three lines
    (ros-package) or a plan (plan); now one line before any file is read."""
    extra = ["--to", "reach"] if command == "plan" else []
    proc = run_cli([command, str(default_spec_path), *extra, "--seed", seed], tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr == (
        f"error: --seed: must be an integer from 0 to {2**32 - 1} (0 <= seed < 2**32), got {seed}\n"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("timeout", ["1e9", "301", "nan", "0"])
def test_plan_timeout_capped(timeout: str, tmp_path: Path, default_spec_path: Path) -> None:
    """Issue 42: `--timeout 1e9` with an unreachable goal planned forever; the cap is in --help."""
    out = tmp_path / "p.yaml"
    args = ["plan", str(default_spec_path), "--to", "reach", "--timeout", timeout, "-o", str(out)]
    proc = run_cli(args, tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("error: --timeout: must be in (0, 300] s, got ")
    assert len(proc.stderr.splitlines()) == 1 and not out.exists()
    helped = run_cli(["plan", "--help"], tmp_path, env={"COLUMNS": "200"})
    assert "Planning time limit [s], at most 300" in helped.stdout
