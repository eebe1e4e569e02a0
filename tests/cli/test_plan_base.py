"""`armcli plan --base` as a user runs it, down to `--execute` on the MuJoCo drive.

The course robot down the corridor scene to a cup on its table (tests/fixtures/plan/
mobile/corridor.yaml): the three plan files and the two run files are written, the JSON
has `plan`'s fields plus the base's, and the executed tool ends within the tolerance of
the target on the ground truth.
"""

from __future__ import annotations

import json
from pathlib import Path

from tests.helpers import DEFAULT_SPEC, FIXTURES, run_cli

CORRIDOR = FIXTURES / "plan" / "mobile" / "corridor.yaml"
TOLERANCE = 0.02  # [m] --tolerance's default: the bound on the executed tool
LOCALISER_HZ = 10.0  # the localiser stand-in's rate (README, docs/mobile.md)


def test_plan_base_execute_writes_and_reaches(tmp_path: Path) -> None:
    out = tmp_path / "run"
    res = run_cli(["plan", str(DEFAULT_SPEC), "--to-xyz", "3.0,0,0.47", "--base", "--scene",
                   str(CORRIDOR), "-o", str(out), "--execute", "--format", "json"])  # fmt: skip
    assert res.returncode == 0, res.stderr
    doc = json.loads(res.stdout)
    assert doc["status"] == "planned"
    for key in ("planning_time_s", "duration_s", "joints", "base_time_s", "base_path_length_m"):
        assert key in doc
    assert doc["base_path_length_m"] > 1.0  # down the corridor (the table is 3 m away)
    assert not doc["execute"]["failed"], doc["execute"]["problems"]
    assert doc["execute"]["tool_error_m"] <= TOLERANCE
    # the follower's ground-truth fixes stand in for a localiser: the output says so
    assert doc["execute"]["localizer_hz"] == LOCALISER_HZ
    names = sorted(p.name for p in out.iterdir())
    assert names == ["arm.yaml", "cmd_vel.yaml", "path.yaml", "run.csv", "run.mcap"]


def test_out_of_reach_without_base_names_it() -> None:
    res = run_cli(["plan", str(DEFAULT_SPEC), "--to-xyz", "1,0.5,0.5"])
    assert res.returncode == 1
    assert "--base plans where to park" in res.stderr


def test_plan_base_execute_text_says_what_stood_in_for_a_localiser(tmp_path: Path) -> None:
    out = tmp_path / "run"
    res = run_cli(["plan", str(DEFAULT_SPEC), "--to-xyz", "1.35,0,0.5", "--base", "-o",
                   str(out), "--execute"])  # fmt: skip
    assert res.returncode == 0, res.stderr
    text = " ".join(res.stdout.split())  # unwrapped
    assert "executed on the MuJoCo drive" in text
    assert (f"followed on the encoder odometry with a {LOCALISER_HZ:g} Hz ground-truth fix (a "
            "stand-in for a localiser such as AMCL)") in text  # fmt: skip
